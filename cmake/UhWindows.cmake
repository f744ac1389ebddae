# The Windows build (cmake/mingw-w64-x86_64.cmake): the modules (core, collette, forcecomp,
# haptico, controllers), the C API's uh.dll and the C API's tests, run under wine64 by ctest.
# Left out, with the reason: the uh program, the service and the live view (Boost.Asio, CLI11,
# cairo, node), the Python module (Debian's python3 is a Linux one), the GoogleTest suites and the
# benchmarks (GoogleTest, Google Benchmark, FCL and Bullet have no mingw builds in Debian).
foreach(option UH_BUILD_APPS UH_BUILD_VIEW UH_BUILD_PYTHON UH_BUILD_BENCHMARKS UH_BUILD_FUZZERS)
  if(${option})
    message(FATAL_ERROR "${option}=ON: not part of the Windows build, which is the modules, uh.dll and the C API's tests (cmake/UhWindows.cmake)")
  endif()
endforeach()
if(UH_SANITIZE)
  message(FATAL_ERROR "UH_SANITIZE: mingw-w64 has no sanitizer runtimes")
endif()

# uh.dll beside the programs that load it
set(CMAKE_RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/bin)

# ctest runs the test programs through cmake/wine-run.sh.in (its own wine prefix in the build
# folder, created once, quietly)
if(CMAKE_CROSSCOMPILING)
  find_program(UH_WINE64 NAMES wine64 wine PATHS /usr/lib/wine NO_CMAKE_FIND_ROOT_PATH)
  if(UH_WINE64)
    configure_file(${CMAKE_CURRENT_LIST_DIR}/wine-run.sh.in ${CMAKE_BINARY_DIR}/wine-run.sh @ONLY
                   FILE_PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE WORLD_READ WORLD_EXECUTE)
    set(CMAKE_CROSSCOMPILING_EMULATOR ${CMAKE_BINARY_DIR}/wine-run.sh)
  else()
    message(STATUS "UnrealHaptics: wine64 not found; the tests build but ctest cannot run them (scripts/install-deps.sh installs wine64)")
  endif()
endif()
