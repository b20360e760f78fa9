emaki_fuzzer(gltf SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/gltf_fuzz.cpp
             DEPS emaki_io emaki_render emaki_scene emaki_core)
