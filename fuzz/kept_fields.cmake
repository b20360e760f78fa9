emaki_fuzzer(kept_fields SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/kept_fields_fuzz.cpp DEPS emaki_store emaki_core)
