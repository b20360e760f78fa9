emaki_fuzzer(exr SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/exr_fuzz.cpp DEPS emaki_io emaki_core)
