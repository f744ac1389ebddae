# Dependencies of the Windows cross build (cmake/mingw-w64-x86_64.cmake). Debian packages no
# mingw builds of fmt, spdlog, assimp or libpng, so that build:
#   - takes the header-only libraries (Eigen, nlohmann-json, readerwriterqueue, fmt in its
#     header-only mode) from the host's Debian packages, each through a folder of its own; the
#     host's /usr/include as a whole never comes near the cross compiler (it holds Linux's C
#     library headers, which would shadow mingw's);
#   - logs to stderr without spdlog (src/core/log_sink_stderr.cpp);
#   - reads meshes with the in-tree OBJ/STL reader instead of assimp (load_mesh() says so for
#     other formats);
#   - leaves out the packing previews (libpng), which only the uh program draws.
find_package(Threads REQUIRED)

# host-headers/<name> -> the host package's folder /usr/include/<name>; host-headers goes on the
# include path as SYSTEM, so that the project's warnings-as-errors skip the libraries' headers
set(UH_HOST_HEADERS_DIR ${CMAKE_BINARY_DIR}/host-headers)
file(MAKE_DIRECTORY ${UH_HOST_HEADERS_DIR})
function(uh_link_host_headers name probe)
  find_path(host_dir_${name} ${name}/${probe} PATHS /usr/include NO_DEFAULT_PATH NO_CMAKE_FIND_ROOT_PATH)
  if(NOT host_dir_${name})
    message(FATAL_ERROR "Windows build: /usr/include/${name}/${probe} not found (scripts/install-deps.sh installs it)")
  endif()
  file(CREATE_LINK ${host_dir_${name}}/${name} ${UH_HOST_HEADERS_DIR}/${name} SYMBOLIC)
endfunction()
function(uh_host_header_target target)
  if(NOT TARGET ${target})
    add_library(${target} INTERFACE IMPORTED)
    set_target_properties(${target} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES ${ARGN})
  endif()
endfunction()

uh_link_host_headers(fmt format.h)
uh_link_host_headers(nlohmann json.hpp)
uh_link_host_headers(readerwriterqueue readerwriterqueue.h)
uh_host_header_target(fmt::fmt ${UH_HOST_HEADERS_DIR})
# fmt's compiled part comes in through its headers (format-inl.h): no library to link
set_target_properties(fmt::fmt PROPERTIES INTERFACE_COMPILE_DEFINITIONS FMT_HEADER_ONLY=1)
uh_host_header_target(nlohmann_json::nlohmann_json ${UH_HOST_HEADERS_DIR})
if(NOT TARGET uh_readerwriterqueue)
  add_library(uh_readerwriterqueue INTERFACE)
  target_include_directories(uh_readerwriterqueue SYSTEM INTERFACE $<BUILD_INTERFACE:${UH_HOST_HEADERS_DIR}>)
endif()

# Eigen's Debian folder holds Eigen only: it goes on the path as it is
find_path(UH_EIGEN_DIR Eigen/Core PATHS /usr/include/eigen3 NO_DEFAULT_PATH NO_CMAKE_FIND_ROOT_PATH)
if(NOT UH_EIGEN_DIR)
  message(FATAL_ERROR "Windows build: /usr/include/eigen3/Eigen/Core not found (scripts/install-deps.sh installs libeigen3-dev)")
endif()
uh_host_header_target(Eigen3::Eigen ${UH_EIGEN_DIR})
