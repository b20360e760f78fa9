emaki_fuzzer(confine SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/confine_fuzz.cpp
             DEPS emaki_view_confine)
