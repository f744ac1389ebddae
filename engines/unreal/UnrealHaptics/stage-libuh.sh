#!/usr/bin/env bash
# Copies libuh and its header into the plugin's third-party module (Source/ThirdParty/UhLibrary).
# usage: stage-libuh.sh [LINUX_BUILD_DIR] [WINDOWS_BUILD_DIR]
#   LINUX_BUILD_DIR    default build/release (libuh.so from `cmake --build`)
#   WINDOWS_BUILD_DIR  default build/windows (uh.dll from the mingw-w64 build, scripts/test.sh's
#                      Windows stage or cmake -DCMAKE_TOOLCHAIN_FILE=cmake/mingw-w64-x86_64.cmake); skipped if absent
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../../.." && pwd)
linux=${1:-$root/build/release}
windows=${2:-$root/build/windows}
module="$here/Source/ThirdParty/UhLibrary"
mkdir -p "$module/include/uh" "$module/lib/Linux" "$module/lib/Win64"
cp "$root/include/uh/uh.h" "$module/include/uh/"
if [ -e "$linux/src/capi/libuh.so" ]; then
  cp -L "$linux/src/capi/libuh.so" "$module/lib/Linux/libuh.so"
  echo "staged $linux/src/capi/libuh.so"
else
  echo "no $linux/src/capi/libuh.so (build the Release tree first)"
fi
dll="$windows/bin/uh.dll"  # the Windows build puts its programs and uh.dll in bin/
if [ -e "$dll" ]; then
  cp "$dll" "$module/lib/Win64/uh.dll"
  echo "staged $dll"
else
  echo "no Windows build in $windows (the mingw-w64 build); Win64 is not staged"
fi
