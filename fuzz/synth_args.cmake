emaki_fuzzer(synth_args SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/synth_args_fuzz.cpp
             DEPS emaki_synth_cli)
