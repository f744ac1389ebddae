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
install(TARGETS uh_core uh_collette uh_forcecomp uh_haptico uh_devices uh_controllers uh_capi uh_service uh_museum uh_museum_service uh_museum_artifacts uh_readerwriterqueue
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
