#!/usr/bin/env bash
# Copies libuh, what it needs and its header into the plugin's third-party module
# (Source/ThirdParty/UhLibrary), for UhLibrary.Build.cs to stage into the plugin's Binaries.
# usage: stage-libuh.sh [LINUX_BUILD_DIR] [WINDOWS_BUILD_DIR]
#   LINUX_BUILD_DIR    default build/release (libuh.so from `cmake --build`)
#   WINDOWS_BUILD_DIR  default build/windows (uh.dll from the mingw-w64 build, scripts/test.sh's
#                      Windows stage or cmake -DCMAKE_TOOLCHAIN_FILE=cmake/mingw-w64-x86_64.cmake); skipped if absent
#   UH_PLUGIN_DIR      (environment) the plugin to stage into; default: the one holding this script
#
# Linux: libuh.so needs shared libraries Debian ships no static archives of (assimp, fmt, spdlog
# and theirs). Each one ldd resolves outside the base system (glibc, libstdc++, libgcc_s) is copied
# beside libuh.so; libuh carries DT_RPATH $ORIGIN, which the loader also applies to its
# dependencies' own dependencies, so a packaged game finds them in the plugin's Binaries/Linux.
# lib/<Platform>/files.txt lists what was staged.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../../.." && pwd)
linux=${1:-$root/build/release}
windows=${2:-$root/build/windows}
plugin=${UH_PLUGIN_DIR:-$here}
module="$plugin/Source/ThirdParty/UhLibrary"
base_system='^(linux-vdso|ld-linux|libc|libm|libdl|librt|libpthread|libstdc\+\+|libgcc_s)\.'

# the Debian package's copyright file of a staged library: a game that ships the library ships it
copyright_of() {
  local package
  # by file name: with merged /usr, dpkg may know the file under /lib or /usr/lib
  package=$(dpkg -S "*/$(basename "$(readlink -f "$1")")" 2>/dev/null | head -1 | cut -d: -f1) || true
  if [ -n "$package" ] && [ -e "/usr/share/doc/$package/copyright" ]; then
    mkdir -p "$2"
    cp "/usr/share/doc/$package/copyright" "$2/$package.copyright"
  else
    echo "warning: no Debian copyright file found for $1 (ship its license by hand)"
  fi
}

stage_linux() {
  local lib="$module/lib/Linux" so="$linux/src/capi/libuh.so"
  if [ ! -e "$so" ]; then
    echo "no $so (build the Release tree first: cmake --build $linux --target uh_capi)"
    return
  fi
  rm -rf "$lib" && mkdir -p "$lib"
  cp -L "$so" "$lib/libuh.so"
  echo libuh.so >"$lib/files.txt"
  # every library the loader resolves for libuh, by the name libuh (or a dependency) asks for
  ldd "$so" | awk '$2 == "=>" && $3 ~ /^\// { print $1, $3 }' | while read -r name path; do
    if [[ ! $name =~ $base_system ]]; then
      cp -L "$path" "$lib/$name"
      echo "$name" >>"$lib/files.txt"
      copyright_of "$path" "$lib/licenses"
    fi
  done
  echo "staged $so and $(($(wc -l <"$lib/files.txt") - 1)) libraries it needs into $lib"
}

stage_windows() {
  local lib="$module/lib/Win64" dll="$windows/bin/uh.dll"  # the Windows build puts uh.dll in bin/
  if [ ! -e "$dll" ]; then
    echo "no Windows build in $windows (the mingw-w64 build); Win64 is not staged"
    return
  fi
  rm -rf "$lib" && mkdir -p "$lib"
  cp "$dll" "$lib/uh.dll"
  echo uh.dll >"$lib/files.txt"
  echo "staged $dll"
}

mkdir -p "$module/include/uh" "$module/data"
cp "$root/include/uh/uh.h" "$module/include/uh/"
# the demo actor draws the bunny of libuh's default scene from this file
cp "$root/assets/meshes/bunny_npm_3674.obj" "$module/data/"
stage_linux
stage_windows
