emaki_fuzzer(exemplar_index SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/exemplar_index_fuzz.cpp DEPS emaki_synth emaki_core)
