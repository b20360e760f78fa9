emaki_fuzzer(farm_state SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/farm_state_fuzz.cpp
             DEPS emaki_farm emaki_core)
