emaki_fuzzer(script_text SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/script_text_fuzz.cpp
             DEPS emaki_farm emaki_core)
