# Every dependency comes from a Debian 12 package; scripts/install-deps.sh installs them.
if(WIN32)
  include(UhWindowsDependencies)
  return()
endif()
find_package(Threads REQUIRED)
find_package(fmt REQUIRED)
find_package(spdlog REQUIRED)
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(assimp REQUIRED)
find_package(PNG REQUIRED)
find_package(nlohmann_json 3.10 REQUIRED)
# Beast and Asio (the service's WebSocket and HTTP server) are header-only
find_package(Boost 1.74 REQUIRED)

# readerwriterqueue ships headers only, without a CMake config.
find_path(UH_READERWRITERQUEUE_INCLUDE_DIR readerwriterqueue/readerwriterqueue.h REQUIRED)
if(NOT TARGET uh_readerwriterqueue)
  add_library(uh_readerwriterqueue INTERFACE)
  # the build's own path only: the installed package config looks the header up again on the
  # consumer's machine, so the install does not carry this machine's include path
  target_include_directories(uh_readerwriterqueue SYSTEM INTERFACE $<BUILD_INTERFACE:${UH_READERWRITERQUEUE_INCLUDE_DIR}>)
endif()

if(UH_BUILD_AUDIO)
  # speech runs the espeak-ng program (GPL-3) at run time; nothing links its library
  find_package(OpenAL REQUIRED)
endif()
if(UH_BUILD_APPS)
  find_package(CLI11 REQUIRED)
endif()
if(UH_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(UH_BUILD_BENCHMARKS)
  find_package(benchmark REQUIRED)
  find_package(fcl REQUIRED)
  find_package(PkgConfig REQUIRED)
  pkg_check_modules(BULLET REQUIRED IMPORTED_TARGET bullet)
endif()
