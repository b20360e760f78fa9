emaki_fuzzer(shot SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/shot_fuzz.cpp DEPS emaki_shot emaki_core)
