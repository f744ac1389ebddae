# Install rules and the CMake package config, so that another project can
#   find_package(UnrealHaptics REQUIRED)
#   target_link_libraries(app PRIVATE uh::haptico)
include(CMakePackageConfigHelpers)

# Windows: what an engine links, uh.dll with its import library and the C header
if(WIN32)
  install(FILES ${PROJECT_SOURCE_DIR}/include/uh/uh.h DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/uh)
  install(TARGETS uh_capi
          RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
  return()
endif()

install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/uh DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(TARGETS uh_core uh_collette uh_forcecomp uh_soft uh_haptico uh_devices uh_scene uh_controllers uh_exploration uh_capi uh_net uh_service uh_museum uh_museum_protocol uh_museum_service uh_museum_artifacts uh_readerwriterqueue
        EXPORT UnrealHapticsTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
if(TARGET uh_cli)
  install(TARGETS uh_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()
install(EXPORT UnrealHapticsTargets NAMESPACE uh::
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/UnrealHaptics)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/UnrealHapticsConfig.cmake.in
  ${PROJECT_BINARY_DIR}/UnrealHapticsConfig.cmake
  INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/UnrealHaptics)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/UnrealHapticsConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/UnrealHapticsConfig.cmake
              ${PROJECT_BINARY_DIR}/UnrealHapticsConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/UnrealHaptics)

# The Python module where Debian's python3 looks (/usr/lib/python3/dist-packages with the /usr
# prefix of the Debian package, scripts/package.sh); it finds libuh in the library folder
if(TARGET uh_python)
  set(UH_INSTALL_PYTHONDIR lib/python3/dist-packages CACHE STRING "Where the Python module is installed, relative to the prefix")
  install(TARGETS uh_python LIBRARY DESTINATION ${UH_INSTALL_PYTHONDIR})
endif()

# Scenes and meshes under share/unrealhaptics, in the repository's layout (a scene names its meshes
# relative to itself): only the project's own public-domain meshes and the scenes that use nothing
# else; the bunny scan and its scenes stay in the repository
set(UH_SHARED_MESHES ball ball_fine block plate slab stylus torus vase)
set(UH_SHARED_SCENES materials materials_block materials_flat materials_stiff thin_wall)
list(TRANSFORM UH_SHARED_MESHES REPLACE "(.+)" "${PROJECT_SOURCE_DIR}/assets/meshes/\\1.obj")
list(TRANSFORM UH_SHARED_SCENES REPLACE "(.+)" "${PROJECT_SOURCE_DIR}/scenes/\\1.json")
install(FILES ${UH_SHARED_MESHES} DESTINATION ${CMAKE_INSTALL_DATADIR}/unrealhaptics/assets/meshes)
install(FILES ${UH_SHARED_SCENES} DESTINATION ${CMAKE_INSTALL_DATADIR}/unrealhaptics/scenes)

# the docs: README and docs/ (share/doc/unrealhaptics, Debian's folder for the package's docs)
install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/unrealhaptics)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs/ DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/unrealhaptics/docs)
