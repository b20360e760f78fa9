# The file side of a shot (shot file, frame sequences, layer store, previews). Its own target
# so that io's image and glTF code does not carry toml++.
emaki_module(shot_io
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/shot_file.cpp ${CMAKE_CURRENT_LIST_DIR}/shot_inputs.cpp
          ${CMAKE_CURRENT_LIST_DIR}/shot_manifest.cpp
          ${CMAKE_CURRENT_LIST_DIR}/studio_passes.cpp
  DEPS emaki_pipeline emaki_io emaki_core
  PRIVATE_DEPS tomlplusplus::tomlplusplus fmt::fmt)
emaki_test(shot_file_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/shot_file_test.cpp DEPS emaki_shot_io)
emaki_test(studio_passes_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/studio_passes_test.cpp DEPS emaki_shot_io)
