#!/usr/bin/env bash
# The package_engines test: the Unity tarball and the Godot zip that package_deb's run of
# scripts/package.sh left in DIST, used as an engine user gets them.
#   Unity: the npm layout (package/), a .meta beside every asset and folder with a GUID of its own,
#   the native plugins' platforms, libuh.so finding its libraries beside it, and the package's
#   managed code compiled from the tarball and its console tests run under mono against the
#   packaged libuh.so alone;
#   Godot: the addon from the zip in a copy of the demo project, its headless tests run with the
#   zip's uh program.
# usage: run_engine_packages_test.sh SOURCE_DIR DIST WORK_DIR
set -euo pipefail
source_dir=$1
dist=$2
work=$3
source "$(dirname "$0")/common.sh"
package_test_init package_engines "$work"
unity_tgz="$dist/org.unrealhaptics.core-$version.tgz"
godot_zip="$dist/unrealhaptics-godot-$version.zip"
[ -f "$unity_tgz" ] || fail "no $unity_tgz"
[ -f "$godot_zip" ] || fail "no $godot_zip"

# --- Unity ---
tar -xzf "$unity_tgz" -C "$work"
package="$work/package"
[ "$(tar -tzf "$unity_tgz" | grep -v '^package/' | wc -l)" -eq 0 ] || fail "the tarball has entries outside package/"
[ "$(/usr/bin/python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["version"])' "$package/package.json")" = "$version" ] ||
  fail "package.json is not version $version"
plugins="$package/Plugins/x86_64"
[ -f "$plugins/libuh.so" ] || fail "the tarball has no Plugins/x86_64/libuh.so"
# every asset and folder Unity imports (not those ending in ~) has its .meta, each GUID once
while IFS= read -r asset; do
  [ -f "$asset.meta" ] || fail "no .meta for ${asset#"$package"/}"
done < <(find "$package" -mindepth 1 -not -path '*~*' -not -name '*.meta')
guids=$(find "$package" -name '*.meta' -exec sed -n 's/^guid: //p' {} +)
[ "$(sort <<<"$guids" | uniq -d | wc -l)" -eq 0 ] || fail "two .meta files share a GUID"
grep -qx "guid: [0-9a-f]\{32\}" "$plugins/libuh.so.meta" || fail "libuh.so.meta has no GUID"
grep -q "OS: Linux" "$plugins/libuh.so.meta" && grep -A3 "Standalone: Linux64" "$plugins/libuh.so.meta" | grep -q "enabled: 1" ||
  fail "libuh.so.meta does not enable the Linux editor and player"
if [ -f "$plugins/uh.dll" ]; then
  grep -q "OS: Windows" "$plugins/uh.dll.meta" || fail "uh.dll.meta does not name Windows"
fi
# libuh finds the libraries it needs beside it (DT_RPATH $ORIGIN), with no LD_LIBRARY_PATH
ldd_out=$(env -u LD_LIBRARY_PATH ldd "$plugins/libuh.so")
grep -q "libassimp.so.5 => $plugins/libassimp.so.5" <<<"$ldd_out" || fail "libuh.so does not load the packaged assimp: $ldd_out"
! grep -q "not found" <<<"$ldd_out" || fail "libuh.so lacks a library: $ldd_out"
# every library bundled beside libuh is in the licence inventory, for the Unity package
bash "$source_dir/tests/package/check_licenses.sh" "$source_dir/docs/licenses.md" --bundled unity "$plugins" ||
  fail "the Unity package bundles a library docs/licenses.md does not list for it"
[ -d "$package/Licenses~" ] || fail "the tarball has no Licenses~ with its bundled libraries' copyright files"
for f in LICENSE.md "Third Party Notices.md"; do [ -f "$package/$f" ] || fail "the tarball has no $f"; done

# the package's managed code, compiled from the tarball, and the console tests against it; mono
# resolves DllImport("uh") through LD_LIBRARY_PATH: the packaged Plugins/x86_64 only
managed="$work/managed"
mkdir -p "$managed"
mcs -nologo -warnaserror -target:library -out:"$managed/UnrealHaptics.dll" "$package"/Runtime/*.cs
mcs -nologo -warnaserror -target:exe -r:"$managed/UnrealHaptics.dll" -out:"$managed/UnrealHaptics.Tests.exe" \
  "$source_dir"/engines/unity/Tests~/Console/*.cs
[ ! -e "$managed/libuh.so" ] || fail "a libuh.so beside the tests"
(cd "$managed" && env LD_LIBRARY_PATH="$plugins" UH_SOURCE_DIR="$source_dir" UH_CACHE_DIR="$work/cache" \
  timeout -k 5 300 mono "$managed/UnrealHaptics.Tests.exe") | tee "$work/unity.log"
grep -qE "^[0-9]+ passed, 0 failed$" "$work/unity.log" || fail "the Unity package's tests failed against the packaged libuh.so"

# --- Godot ---
# the demo project copied where its scene's mesh path (../../../assets) still reaches the meshes
godot="$work/godot"
mkdir -p "$godot/engines/godot"
cp -r "$source_dir/engines/godot/demo" "$godot/engines/godot/demo"
ln -s "$source_dir/assets" "$godot/assets"
rm -rf "$godot/engines/godot/demo/addons"
(cd "$godot/engines/godot/demo" && unzip -q "$godot_zip")
uh="$godot/engines/godot/demo/addons/unrealhaptics/bin/uh"
[ -x "$uh" ] || fail "the Godot zip has no executable addons/unrealhaptics/bin/uh"
for f in LICENSE THIRD_PARTY_NOTICES.md; do
  [ -f "$godot/engines/godot/demo/addons/unrealhaptics/$f" ] || fail "the Godot zip has no addons/unrealhaptics/$f"
done
[ "$("$uh" --version)" = "uh $version" ] || fail "the Godot zip's uh is not version $version"
grep -qx "version=\"$version\"" "$godot/engines/godot/demo/addons/unrealhaptics/plugin.cfg" || fail "plugin.cfg is not version $version"
UH_PROGRAM="$uh" UH_GODOT_PROJECT="$godot/engines/godot/demo" UH_CACHE_DIR="$work/cache" \
  bash "$source_dir/scripts/godot-test.sh" "$godot" | tee "$work/godot.log"
grep -qE "^[0-9]+ passed, 0 failed$" "$work/godot.log" || fail "the Godot addon's tests failed with the packaged uh"
echo "package_engines: the Unity tarball and the Godot zip work as packaged"
