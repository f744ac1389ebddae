#!/usr/bin/env bash
# The CApi.windows_zip test of the Windows build: the zip scripts/package.sh makes of it, unpacked;
# the C API's test program (built against the build's uh.dll) runs under wine beside the zip's
# uh.dll, and the zip holds the import library, the header and the C API's docs.
# usage: run_windows_zip_test.sh SOURCE_DIR WINDOWS_BUILD_DIR WINE_RUN TEST_PROGRAM WORK_DIR
set -euo pipefail
source_dir=$1
build_dir=$2
wine_run=$3
test_program=$4
work=$5
source "$(dirname "$0")/common.sh"
package_test_init windows_zip "$work"

bash "$source_dir/scripts/package.sh" --windows-only --windows-build-dir "$build_dir" --no-build --out "$work/dist"
name="unrealhaptics-$version-windows-x64"
(cd "$work/dist" && sha256sum --check --quiet SHA256SUMS) || fail "SHA256SUMS does not match"
(cd "$work" && unzip -q "dist/$name.zip")
for f in bin/uh.dll lib/libuh.dll.a include/uh/uh.h doc/capi.md LICENSE doc/licenses.md; do
  [ -f "$work/$name/$f" ] || fail "the zip has no $f"
done
# the DLLs uh.dll imports are in the licence inventory
bash "$source_dir/tests/package/check_licenses.sh" "$source_dir/docs/licenses.md" uh.dll "$work/$name/bin/uh.dll" ||
  fail "uh.dll imports a library docs/licenses.md does not list for it"
cp "$test_program" "$work/$name/bin/"
# the zip's uh.dll is the one beside the program: Windows loads a DLL from the program's folder first
UH_CACHE_DIR="$work/cache" "$wine_run" "$work/$name/bin/$(basename "$test_program")" version ||
  fail "the C API's version test failed against the zip's uh.dll"
echo "windows_zip: $name.zip holds a working uh.dll"
