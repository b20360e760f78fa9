emaki_fuzzer(png SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/png_fuzz.cpp DEPS emaki_io emaki_core)
