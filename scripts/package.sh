#!/usr/bin/env bash
# Builds the release artifacts under dist/, all versioned by project(VERSION) in CMakeLists.txt:
#   unrealhaptics_<v>_amd64.deb   uh, libuh.so, headers, the CMake package, the Python module,
#                                 scenes and meshes, docs and uh's man page (docs/packaging.md)
#   SHA256SUMS                    the artifacts' checksums
# usage: package.sh [--build-dir DIR] [--no-build] [--out DIR]
#   --build-dir DIR  the Linux Release build to package (default build/package, configured here)
#   --no-build       package DIR as it is (the package_deb test does so with the Release build)
#   --out DIR        where the artifacts go (default dist/)
set -euo pipefail
source "$(dirname "$0")/common.sh"

build_dir=build/package
build=1
out="$uh_root/dist"
while [ $# -gt 0 ]; do
  case $1 in
    --build-dir) build_dir=$2; shift 2 ;;
    --no-build) build=0; shift ;;
    --out) out=$2; shift 2 ;;
    *) echo "package: unknown argument $1 (see the script's header)" >&2; exit 2 ;;
  esac
done
case $build_dir in /*) ;; *) build_dir="$uh_root/$build_dir" ;; esac

version=$(sed -nE 's/^project\([A-Za-z]+ VERSION ([0-9]+\.[0-9]+\.[0-9]+).*/\1/p' "$uh_root/CMakeLists.txt")
[ -n "$version" ] || { echo "package: no project(VERSION) in CMakeLists.txt" >&2; exit 1; }
arch=$(dpkg --print-architecture)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$out"

if [ "$build" = 1 ]; then
  bash "$uh_root/scripts/install-deps.sh"
  echo "== build (Release, $build_dir) =="
  uh_build "${build_dir#"$uh_root"/}" -- -DCMAKE_BUILD_TYPE=Release -DUH_BUILD_TESTS=OFF -DUH_BUILD_BENCHMARKS=OFF
fi

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
Recommends: ${dev_recommends}
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

package_deb
(cd "$out" && sha256sum -- *.deb >SHA256SUMS)
echo "== $out/SHA256SUMS =="
cat "$out/SHA256SUMS"
