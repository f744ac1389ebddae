#!/usr/bin/env bash
# Builds the release artifacts under dist/, all versioned by project(VERSION) in CMakeLists.txt:
#   unrealhaptics_<v>_amd64.deb   uh, libuh.so, headers, the CMake package, the Python module,
#                                 scenes and meshes, docs and uh's man page (docs/packaging.md)
#   unrealhaptics-<v>-windows-x64.zip   uh.dll, its import library, uh.h, the C API's docs
#   org.unrealhaptics.core-<v>.tgz      the Unity package with libuh.so (and uh.dll) in Plugins/x86_64
#   unrealhaptics-godot-<v>.zip         the Godot addon with the Linux uh program in it
#   SHA256SUMS                    the artifacts' checksums
# usage: package.sh [--build-dir DIR] [--windows-build-dir DIR] [--no-build] [--windows-only] [--out DIR]
#   --build-dir DIR          the Linux Release build to package (default build/package, configured here)
#   --windows-build-dir DIR  the mingw-w64 build (default build/windows); without its uh.dll
#                            (with --no-build) the Windows zip and the Unity package's uh.dll are left out
#   --no-build               package the builds as they are (the package tests do so)
#   --windows-only           the Windows zip alone (the Windows build's test of it)
#   --out DIR                where the artifacts go (default dist/)
set -euo pipefail
source "$(dirname "$0")/common.sh"

build_dir=build/package
windows_dir=build/windows
build=1
linux=1
out="$uh_root/dist"
while [ $# -gt 0 ]; do
  case $1 in
    --build-dir) build_dir=$2; shift 2 ;;
    --windows-build-dir) windows_dir=$2; shift 2 ;;
    --no-build) build=0; shift ;;
    --windows-only) linux=0; shift ;;
    --out) out=$2; shift 2 ;;
    *) echo "package: unknown argument $1 (see the script's header)" >&2; exit 2 ;;
  esac
done
case $build_dir in /*) ;; *) build_dir="$uh_root/$build_dir" ;; esac
case $windows_dir in /*) ;; *) windows_dir="$uh_root/$windows_dir" ;; esac

version=$(uh_project_version)
[ -n "$version" ] || { echo "package: no project(VERSION) in CMakeLists.txt" >&2; exit 1; }
arch=$(dpkg --print-architecture)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$out"

if [ "$build" = 1 ]; then
  bash "$uh_root/scripts/install-deps.sh"
fi
if [ "$build" = 1 ] && [ "$linux" = 1 ]; then
  echo "== build (Release, $build_dir) =="
  uh_build "${build_dir#"$uh_root"/}" -- -DCMAKE_BUILD_TYPE=Release -DUH_BUILD_TESTS=OFF -DUH_BUILD_BENCHMARKS=OFF
fi
if [ "$build" = 1 ]; then
  echo "== build (Windows x64, mingw-w64, $windows_dir) =="
  uh_build "${windows_dir#"$uh_root"/}" uh_capi -- -DCMAKE_TOOLCHAIN_FILE="$uh_root/cmake/mingw-w64-x86_64.cmake" \
    -DCMAKE_BUILD_TYPE=Release
fi
uh_dll="$windows_dir/bin/uh.dll"
[ -f "$uh_dll" ] || { echo "package: no $uh_dll: the Windows zip and the Unity package's uh.dll are left out"; uh_dll=""; }

# Depends: of the package's ELF files, from the Debian packages their libraries come from
# (dpkg-shlibdeps wants a source package's layout: ROOT is debian/<package>/ beside debian/control)
debian_depends() {
  local root=$1 layout
  layout=$(dirname "$(dirname "$root")")
  printf 'Source: unrealhaptics\n\nPackage: unrealhaptics\nArchitecture: any\n' >"$layout/debian/control"
  local elf=()
  while IFS= read -r f; do
    if [ "$(head -c 4 "$f" | od -An -c | tr -d ' ')" = '177ELF' ]; then elf+=("debian/unrealhaptics/${f#"$root"/}"); fi
  done < <(find "$root" -type f \( -perm -u+x -o -name '*.so*' \))
  # libuh is the package's own: its users find it in the package
  (cd "$layout" && dpkg-shlibdeps -O -ldebian/unrealhaptics/usr/lib --ignore-missing-info "${elf[@]}" 2>"$work/shlibdeps.log") ||
    { echo "package: dpkg-shlibdeps failed:" >&2; cat "$work/shlibdeps.log" >&2; return 1; }
}

# the Python module is built for one python3 minor version (its file name says which)
python_depends() {
  local module
  module=$(find "$1/usr/lib/python3/dist-packages" -name 'unrealhaptics.cpython-*.so' | head -1)
  [ -n "$module" ] || return 0
  local minor
  minor=$(basename "$module" | sed -E 's/^unrealhaptics\.cpython-3([0-9]+)-.*/\1/')
  echo "python3 (>= 3.$minor~), python3 (<< 3.$((minor + 1)))"
}

# what find_package(UnrealHaptics) looks up on the user's machine (cmake/UnrealHapticsConfig.cmake.in)
dev_recommends="cmake, libfmt-dev, libspdlog-dev, libeigen3-dev, libassimp-dev, libpng-dev, nlohmann-json3-dev, libboost-dev, libreaderwriterqueue-dev"

package_deb() {
  local root="$work/debian/unrealhaptics" deb="$out/unrealhaptics_${version}_${arch}.deb"
  echo "== $(basename "$deb") =="
  DESTDIR="$root" cmake --install "$build_dir" --prefix /usr >/dev/null
  [ -x "$root/usr/bin/uh" ] || { echo "package: the build has no uh program" >&2; exit 1; }
  "$root/usr/bin/uh" --version | grep -qx "uh $version" ||
    { echo "package: $build_dir's uh is not version $version (rebuild it)" >&2; exit 1; }
  mkdir -p "$root/usr/share/man/man1"
  LD_LIBRARY_PATH="$root/usr/lib" help2man --no-info --no-discard-stderr --section 1 \
    --name "haptic rendering of closed meshes: sphere trees, sessions, the service" \
    "$root/usr/bin/uh" | gzip -9n >"$root/usr/share/man/man1/uh.1.gz"

  # Debian's copyright file (machine-readable, packaging/copyright; docs/licenses.md explains it)
  install -D -m 644 "$uh_root/packaging/copyright" "$root/usr/share/doc/unrealhaptics/copyright"

  mkdir -p "$root/DEBIAN"
  local depends
  depends=$(debian_depends "$root" | sed -n 's/^shlibs:Depends=//p')
  [ -n "$depends" ] || { echo "package: dpkg-shlibdeps found no dependencies" >&2; exit 1; }
  local python
  python=$(python_depends "$root")
  cat >"$root/DEBIAN/control" <<EOF
Package: unrealhaptics
Version: $version
Architecture: $arch
Maintainer: UnrealHaptics contributors
Installed-Size: $(du -sk --exclude=DEBIAN "$root" | cut -f1)
Depends: ${depends}${python:+, $python}
Recommends: espeak-ng, ${dev_recommends}
Section: science
Priority: optional
Description: haptic rendering for game engines (Inner Sphere Trees, penalty forces)
 UnrealHaptics renders forces between closed meshes at 1 kHz: the uh program,
 libuh (the C API), the C++ modules' headers and CMake package
 (find_package(UnrealHaptics)), and the Python module unrealhaptics.
EOF
  dpkg-deb --root-owner-group -Zxz --build "$root" "$deb" >/dev/null
  echo "$deb"
}

package_windows() {
  local name="unrealhaptics-${version}-windows-x64" root="$work/windows"
  echo "== $name.zip =="
  DESTDIR="$root" cmake --install "$windows_dir" --prefix "/$name" >/dev/null
  mkdir -p "$root/$name/doc"
  cp "$uh_root/docs/capi.md" "$root/$name/doc/"
  cp "$uh_root/LICENSE" "$root/$name/"
  cp "$uh_root/docs/licenses.md" "$root/$name/doc/"
  (cd "$root" && zip -qrX "$out/$name.zip" "$name")
}

# Unity's import settings: a .meta beside every asset and folder, its GUID derived from the path so
# that every release gives an asset the same one (scenes reference scripts by GUID)
unity_meta() {
  local asset=$1 relative=$2 importer=$3 guid
  guid=$(printf 'org.unrealhaptics.core/%s' "$relative" | md5sum | cut -c1-32)
  {
    printf 'fileFormatVersion: 2\nguid: %s\n' "$guid"
    if [ -d "$asset" ]; then printf 'folderAsset: yes\n'; fi
    printf '%s:\n  externalObjects: {}\n' "$importer"
    case $importer in
      MonoImporter) printf '  serializedVersion: 2\n  defaultReferences: []\n  executionOrder: 0\n  icon: {instanceID: 0}\n' ;;
      PluginImporter) unity_plugin_platforms "$(basename "$asset")" ;;
    esac
    printf '  userData: \n  assetBundleName: \n  assetBundleVariant: \n'
  } >"$asset.meta"
}

# a native plugin's platforms: the .so files for the Linux editor and player, uh.dll for Windows'
unity_plugin_platforms() {
  local os=Linux player=Linux64 other=Win64
  case $1 in *.dll) os=Windows player=Win64 other=Linux64 ;; esac
  printf '  serializedVersion: 2\n  iconMap: {}\n  executionOrder: {}\n  defineConstraints: []\n'
  printf '  isPreloaded: 0\n  isOverridable: 0\n  isExplicitlyReferenced: 0\n  validateReferences: 1\n'
  printf '  platformData:\n'
  printf '  - first:\n      Any: \n    second:\n      enabled: 0\n      settings: {}\n'
  printf '  - first:\n      Editor: Editor\n    second:\n      enabled: 1\n      settings:\n        CPU: x86_64\n        DefaultValueInitialized: true\n        OS: %s\n' "$os"
  printf '  - first:\n      Standalone: %s\n    second:\n      enabled: 1\n      settings:\n        CPU: x86_64\n' "$player"
  printf '  - first:\n      Standalone: %s\n    second:\n      enabled: 0\n      settings:\n        CPU: None\n' "$other"
}

unity_importer() {
  case $1 in
    *.cs) echo MonoImporter ;;
    *.asmdef) echo AssemblyDefinitionImporter ;;
    package.json) echo PackageManifestImporter ;;
    *.md) echo TextScriptImporter ;;
    *.so | *.so.* | *.dll) echo PluginImporter ;;
    *) echo DefaultImporter ;;
  esac
}

# The Unity package as npm packs it (one folder, package/): the manifest, README, Runtime/, and
# Plugins/x86_64 with libuh.so, the shared libraries it needs (found beside it through its RPATH
# $ORIGIN, staged as for the Unreal plugin) and uh.dll; their Debian copyright files in Licenses~
package_unity() {
  local name="org.unrealhaptics.core-${version}.tgz" root="$work/unity/package" staged="$work/unity-staged"
  echo "== $name =="
  mkdir -p "$root/Plugins/x86_64"
  cp "$uh_root/engines/unity/package.json" "$uh_root/engines/unity/README.md" "$root/"
  # the licence and the third-party notices, under the names Unity's package layout gives them
  cp "$uh_root/LICENSE" "$root/LICENSE.md"
  cp "$uh_root/docs/licenses.md" "$root/Third Party Notices.md"
  cp -r "$uh_root/engines/unity/Runtime" "$root/"
  UH_PLUGIN_DIR="$staged" bash "$uh_root/engines/unreal/UnrealHaptics/stage-libuh.sh" "$build_dir" /nonexistent >/dev/null
  local lib="$staged/Source/ThirdParty/UhLibrary/lib/Linux"
  [ -f "$lib/libuh.so" ] || { echo "package: libuh.so was not staged" >&2; exit 1; }
  while read -r file; do cp "$lib/$file" "$root/Plugins/x86_64/"; done <"$lib/files.txt"
  if [ -d "$lib/licenses" ]; then cp -r "$lib/licenses" "$root/Licenses~"; fi
  if [ -n "$uh_dll" ]; then cp "$uh_dll" "$root/Plugins/x86_64/"; fi
  local asset
  while IFS= read -r asset; do
    unity_meta "$asset" "${asset#"$root"/}" "$(unity_importer "$(basename "$asset")")"
  done < <(find "$root" -mindepth 1 -not -path '*~*' -not -name '*.meta')
  tar --sort=name --owner=0 --group=0 --numeric-owner --mtime="@0" -C "$work/unity" -czf "$out/$name" package
}

# The Godot addon in the asset library's layout (addons/unrealhaptics/), with the Linux uh program
# in addons/unrealhaptics/bin/ (the HapticManager starts it: its uh_program or UH_PROGRAM names it)
package_godot() {
  local name="unrealhaptics-godot-${version}.zip" root="$work/godot"
  echo "== $name =="
  mkdir -p "$root/addons"
  cp -r "$uh_root/engines/godot/addons/unrealhaptics" "$root/addons/"
  cp "$uh_root/LICENSE" "$root/addons/unrealhaptics/LICENSE"
  cp "$uh_root/docs/licenses.md" "$root/addons/unrealhaptics/THIRD_PARTY_NOTICES.md"
  mkdir -p "$root/addons/unrealhaptics/bin"
  cp "$build_dir/apps/uh/uh" "$root/addons/unrealhaptics/bin/uh"
  (cd "$root" && zip -qrX "$out/$name" addons)
}

rm -f "$out"/unrealhaptics_*.deb "$out"/unrealhaptics-*.zip "$out"/org.unrealhaptics.core-*.tgz "$out/SHA256SUMS"
if [ "$linux" = 1 ]; then package_deb; fi
if [ -n "$uh_dll" ]; then package_windows; fi
if [ "$linux" = 1 ]; then
  package_unity
  package_godot
fi
(cd "$out" && shopt -s nullglob && files=(*.deb *.zip *.tgz) && [ ${#files[@]} -gt 0 ] &&
  sha256sum -- "${files[@]}" >SHA256SUMS) || { echo "package: no artifact made" >&2; exit 1; }
echo "== $out/SHA256SUMS =="
cat "$out/SHA256SUMS"
