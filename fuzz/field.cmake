emaki_fuzzer(field SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/field_fuzz.cpp DEPS emaki_store emaki_core)
