# `cmake --install build/release --prefix P` and the Debian package (docs/install.md). The tree
# is relocatable: nothing in it names P.
#
#   P/bin/emaki                          emaki's own libraries linked in (static)
#   P/lib/emaki/libemaki_io_oiio.so      the OpenImageIO plugin, found from /proc/self/exe
#   P/lib/python3/dist-packages/         the Python module and its stub (Debian's python3 path)
#   P/share/emaki/blender/emaki_blender.zip   the Blender add-on (one package, one bl_info)
#   P/share/emaki/examples, docs         the bundled shots and their data; the documentation
#   P/share/man/man1/emaki.1             made from the CLI's own --help (cmake/man_page.cmake)
#   P/include/emaki, P/lib/libemaki_*.a, P/lib/cmake/emaki   find_package(emaki): emaki::synth...
#
# Two components: `runtime` (the package `emaki`) and `dev` (`emaki-dev`: headers, static
# libraries, CMake package).

# ---- runtime --------------------------------------------------------------------------------
install(TARGETS emaki RUNTIME DESTINATION bin COMPONENT runtime)
install(TARGETS emaki_io_oiio LIBRARY DESTINATION lib/emaki COMPONENT runtime)
# Installing over an older emaki keeps no module of another Python beside the new one
# (python/CMakeLists.txt installs it after this runs); the plugin's name never changes.
if(EMAKI_PYTHON_MODULE)
  install(CODE [[
    file(GLOB old "$ENV{DESTDIR}${CMAKE_INSTALL_PREFIX}/lib/python3/dist-packages/emaki.cpython-*.so")
    if(old)
      file(REMOVE ${old})
    endif()
  ]] COMPONENT runtime)
endif()

install(DIRECTORY examples/ DESTINATION share/emaki/examples COMPONENT runtime
        PATTERN "out" EXCLUDE PATTERN "__pycache__" EXCLUDE)
install(DIRECTORY docs/ DESTINATION share/emaki/docs COMPONENT runtime)
install(FILES README.md DESTINATION share/emaki COMPONENT runtime)

# The man page: every command's --help, run on the built binary, so it cannot drift from it.
set(EMAKI_MAN_PAGE ${PROJECT_BINARY_DIR}/man/emaki.1)
add_custom_command(OUTPUT ${EMAKI_MAN_PAGE}
  COMMAND ${CMAKE_COMMAND} -DEMAKI=$<TARGET_FILE:emaki> -DOUT=${EMAKI_MAN_PAGE}
          -P ${PROJECT_SOURCE_DIR}/cmake/man_page.cmake
  DEPENDS emaki ${PROJECT_SOURCE_DIR}/cmake/man_page.cmake
  COMMENT "emaki.1 from emaki --help" VERBATIM)
add_custom_target(emaki_man_page ALL DEPENDS ${EMAKI_MAN_PAGE})
install(FILES ${EMAKI_MAN_PAGE} DESTINATION share/man/man1 COMPONENT runtime)

# The Blender add-on: tools/blender's two scripts in one package folder, emaki_blender/, whose
# __init__.py holds the one bl_info (its version is the project's), zipped for Blender's
# Preferences > Add-ons > Install.
set(EMAKI_ADDON_DIR ${PROJECT_BINARY_DIR}/blender/emaki_blender)
set(EMAKI_ADDON_ZIP ${PROJECT_BINARY_DIR}/blender/emaki_blender.zip)
configure_file(tools/blender/emaki_blender/__init__.py.in ${EMAKI_ADDON_DIR}/__init__.py @ONLY)
add_custom_command(OUTPUT ${EMAKI_ADDON_ZIP}
  COMMAND ${CMAKE_COMMAND} -E copy ${PROJECT_SOURCE_DIR}/tools/blender/emaki_passes.py
          ${PROJECT_SOURCE_DIR}/tools/blender/emaki_stylize.py ${EMAKI_ADDON_DIR}/
  COMMAND ${CMAKE_COMMAND} -E rm -f ${EMAKI_ADDON_ZIP}
  COMMAND ${CMAKE_COMMAND} -E tar cf ${EMAKI_ADDON_ZIP} --format=zip
          emaki_blender/__init__.py emaki_blender/emaki_passes.py emaki_blender/emaki_stylize.py
  WORKING_DIRECTORY ${PROJECT_BINARY_DIR}/blender
  DEPENDS ${EMAKI_ADDON_DIR}/__init__.py ${PROJECT_SOURCE_DIR}/tools/blender/emaki_passes.py
          ${PROJECT_SOURCE_DIR}/tools/blender/emaki_stylize.py
  COMMENT "the Blender add-on, emaki_blender.zip" VERBATIM)
add_custom_target(emaki_blender_addon ALL DEPENDS ${EMAKI_ADDON_ZIP})
install(FILES ${EMAKI_ADDON_ZIP} DESTINATION share/emaki/blender COMPONENT runtime)
install(PROGRAMS tools/hatching/make_hatching.py DESTINATION share/emaki/tools COMPONENT runtime)

# ---- dev: find_package(emaki CONFIG) ----------------------------------------------------------
# Every module library (each emaki_module) as emaki::NAME, so a new module is exported with
# the others. Static, so the export carries their private dependencies as link-only:
# emakiConfig.cmake finds them.
get_property(EMAKI_EXPORTED GLOBAL PROPERTY EMAKI_MODULES)
install(TARGETS ${EMAKI_EXPORTED} EXPORT emakiTargets
        ARCHIVE DESTINATION lib COMPONENT dev)
install(DIRECTORY src/ DESTINATION include/emaki COMPONENT dev
        FILES_MATCHING PATTERN "*.h" PATTERN "test_images.h" EXCLUDE)
install(EXPORT emakiTargets NAMESPACE emaki:: DESTINATION lib/cmake/emaki COMPONENT dev)
include(CMakePackageConfigHelpers)
configure_package_config_file(cmake/emakiConfig.cmake.in
  ${PROJECT_BINARY_DIR}/cmake/emakiConfig.cmake INSTALL_DESTINATION lib/cmake/emaki)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/cmake/emakiConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/cmake/emakiConfig.cmake
              ${PROJECT_BINARY_DIR}/cmake/emakiConfigVersion.cmake
        DESTINATION lib/cmake/emaki COMPONENT dev)

# ---- the Debian packages (cpack -G DEB in build/release) --------------------------------------
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME emaki)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_CONTACT "emaki maintainers <emaki@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "stylize 3D animation by example")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_ALL runtime dev)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION graphics)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_NAME emaki)
set(CPACK_DEBIAN_RUNTIME_DESCRIPTION
    "stylize 3D animation by example\n guided patch-based synthesis (EbSynth-compatible), guide\n passes of glTF scenes, shots with layers, temporal coherence and a Slurm farm.")
# The libraries the binary, the plugin and the Python module link, as dpkg-shlibdeps finds their
# Debian runtime packages; then what emaki runs or imports.
set(CPACK_DEBIAN_RUNTIME_PACKAGE_SHLIBDEPS ON)
if(EMAKI_PYTHON_MODULE)
  math(EXPR next_minor "${Python_VERSION_MINOR} + 1")
  set(CPACK_DEBIAN_RUNTIME_PACKAGE_DEPENDS "python3 (>= ${Python_VERSION_MAJOR}.${Python_VERSION_MINOR}), \
python3 (<< ${Python_VERSION_MAJOR}.${next_minor}), python3-numpy")
endif()
set(CPACK_DEBIAN_RUNTIME_PACKAGE_RECOMMENDS "ffmpeg")
set(CPACK_DEBIAN_RUNTIME_PACKAGE_SUGGESTS "blender, slurm-client")
set(CPACK_DEBIAN_DEV_PACKAGE_NAME emaki-dev)
set(CPACK_DEBIAN_DEV_DESCRIPTION
    "stylize 3D animation by example - C++ development files\n emaki's engine and shot API as CMake targets: find_package(emaki CONFIG), emaki::synth, emaki::shot.")
set(CPACK_DEBIAN_DEV_PACKAGE_DEPENDS
    "emaki (= ${PROJECT_VERSION}), libtbb-dev, libglm-dev, libfmt-dev, libpng-dev, zlib1g-dev, libdeflate-dev, libtinygltf-dev, libtomlplusplus-dev, libopencolorio-dev, pkg-config")
set(CPACK_DEBIAN_DEV_PACKAGE_SECTION libdevel)
include(CPack)
