#!/usr/bin/env bash
# The package_deb test: the Debian package of a Release build (scripts/package.sh --no-build),
# unpacked with dpkg-deb -x into a scratch root and used from there alone, as an installed one is.
# usage: run_package_test.sh BUILD_DIR WORK_DIR
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
source_dir=$(cd "$here/../.." && pwd)
build_dir=$1
work=$2
source "$here/common.sh"
package_test_init package_deb "$work"

# the Linux artifacts of this build only: a Windows build folder may hold another version's uh.dll
bash "$source_dir/scripts/package.sh" --build-dir "$build_dir" --windows-build-dir "$work/no-windows-build" \
  --no-build --out "$work/dist"
deb="$work/dist/unrealhaptics_${version}_$(dpkg --print-architecture).deb"
[ -f "$deb" ] || fail "no $deb"
(cd "$work/dist" && sha256sum --check --quiet SHA256SUMS) || fail "SHA256SUMS does not match"

# Depends names the libraries uh and libuh link, and the python3 the module is built for
depends=$(dpkg-deb -f "$deb" Depends)
echo "Depends: $depends"
depends_names=$(tr ',' '\n' <<<"$depends" | sed -E 's/^ *//; s/ .*//')
for package in libc6 libstdc++6 libassimp5 libfmt9 python3; do
  grep -qxF "$package" <<<"$depends_names" || fail "Depends lacks $package"
done

root="$work/root"
dpkg-deb -x "$deb" "$root"
usr="$root/usr"
# what the package holds, by the names its users rely on
for f in bin/uh lib/libuh.so lib/libuh.so.0 include/uh/uh.h lib/cmake/UnrealHaptics/UnrealHapticsConfig.cmake \
         share/man/man1/uh.1.gz share/doc/unrealhaptics/README.md share/unrealhaptics/scenes/thin_wall.json; do
  [ -e "$usr/$f" ] || fail "the package has no /usr/$f"
done
# the copyright file is machine-readable: the format named, every License: of a Files stanza with
# its own paragraph (or Debian's common licence text)
copyright="$usr/share/doc/unrealhaptics/copyright"
[ -f "$copyright" ] || fail "the package has no /usr/share/doc/unrealhaptics/copyright"
/usr/bin/python3 - "$copyright" <<'PY' || fail "the copyright file is not machine-readable (DEP-5)"
import re, sys
paragraphs = [p for p in open(sys.argv[1]).read().split("\n\n") if p.strip()]
assert paragraphs[0].startswith("Format: https://www.debian.org/doc/packaging-manuals/copyright-format/1.0/"), "no Format line"
defined = {re.match(r"License: (.+)", p).group(1) for p in paragraphs if p.startswith("License: ") and "\n " in p}
used = set()
for p in paragraphs:
    if p.startswith("Files: "):
        names = re.search(r"^License: (.+)$", p, re.M).group(1)
        used.update(n.strip() for n in names.split(" and "))
missing = used - defined
assert not missing, f"no License paragraph for {missing}"
PY
[ "$(readelf -d "$usr/lib/libuh.so.0" | sed -nE 's/.*SONAME.*\[(.*)\]/\1/p')" = libuh.so.0 ] || fail "libuh's soname is not libuh.so.0"
# a shipped scene names only meshes the package holds
for scene in "$usr"/share/unrealhaptics/scenes/*.json; do
  for mesh in $(grep -oE '"[^"]+\.obj"' "$scene" | tr -d '"'); do
    [ -f "$(dirname "$scene")/$mesh" ] || fail "$(basename "$scene") names $mesh, which the package lacks"
  done
done

# the unpacked root alone: no build or source folder on any path
in_root() {
  env -i HOME="$work" PATH="$usr/bin:/usr/bin:/bin" LD_LIBRARY_PATH="$usr/lib" \
    PYTHONPATH="$usr/lib/python3/dist-packages" UH_CACHE_DIR="$work/cache" "$@"
}
[ "$(in_root sh -c 'command -v uh')" = "$usr/bin/uh" ] || fail "uh on PATH is not the package's"
[ "$(in_root uh --version)" = "uh $version" ] || fail "uh --version is not 'uh $version'"
in_root uh run --seconds 1 >"$work/run.txt" || fail "uh run --seconds 1 failed: $(cat "$work/run.txt")"
in_root uh run "$usr/share/unrealhaptics/scenes/thin_wall.json" --seconds 1 >"$work/run_scene.txt" ||
  fail "uh run thin_wall.json failed: $(cat "$work/run_scene.txt")"
(cd "$work" && in_root /usr/bin/python3 -c "
import unrealhaptics as uh
assert uh.__file__.startswith('$usr/'), uh.__file__
assert uh.__version__ == '$version', uh.__version__
# 1 s: the default raster starts in the bunny's flank, which the proxy leaves free until it is out (0.6 s)
with uh.Session.open() as s:
    report = s.run_stepped(1.0, 4)
assert report['haptic']['ticks'] == 1000 and report['contact']['ticks'] > 0, report
print('python: stepped session of', report['haptic']['ticks'], 'ticks')
") || fail "the Python module failed"

# the repository's consumer project, built against the unpacked root's CMake package
in_root cmake -S "$source_dir/tests/consumer/project" -B "$work/consumer" -G Ninja \
  -DCMAKE_PREFIX_PATH="$usr" -DCMAKE_BUILD_TYPE=Release -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF >/dev/null ||
  fail "configuring the consumer against the package failed"
grep -q "UnrealHaptics_DIR:PATH=$usr/lib/cmake/UnrealHaptics" "$work/consumer/CMakeCache.txt" ||
  fail "the consumer found another UnrealHaptics package"
in_root cmake --build "$work/consumer" >/dev/null || fail "building the consumer against the package failed"
in_root "$work/consumer/uh_consumer" | grep -q "consumer ok" || fail "the consumer failed"
in_root "$work/consumer/uh_capi_consumer" | grep -q "capi consumer ok" || fail "the C API consumer failed"
echo "package_deb: $(basename "$deb") works from its unpacked root"
