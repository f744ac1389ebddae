# Cross build for Windows x64 with Debian's mingw-w64 (posix thread model: std::thread and
# std::mutex come from winpthreads). Build and test:
#   cmake -S . -B build/windows -G Ninja -DCMAKE_TOOLCHAIN_FILE=cmake/mingw-w64-x86_64.cmake
#   cmake --build build/windows --target uh_capi uh_capi_test && ctest --test-dir build/windows
# Builds the modules and the C API's uh.dll (cmake/UhWindows.cmake says what is left out); ctest
# runs the C API's tests under wine64 (cmake/wine-run.sh.in).
set(CMAKE_SYSTEM_NAME Windows)
set(CMAKE_SYSTEM_PROCESSOR x86_64)
set(UH_MINGW_TRIPLE x86_64-w64-mingw32)
set(CMAKE_C_COMPILER ${UH_MINGW_TRIPLE}-gcc-posix)
set(CMAKE_CXX_COMPILER ${UH_MINGW_TRIPLE}-g++-posix)
set(CMAKE_RC_COMPILER ${UH_MINGW_TRIPLE}-windres)

# libraries and headers of the target only; programs (cmake, node, ...) from the host
set(CMAKE_FIND_ROOT_PATH /usr/${UH_MINGW_TRIPLE})
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)

# the C and C++ runtimes and winpthreads linked in: uh.dll and the test programs need no
# compiler DLLs beside them
set(CMAKE_EXE_LINKER_FLAGS_INIT "-static")
set(CMAKE_SHARED_LINKER_FLAGS_INIT "-static")
