#!/usr/bin/env bash
# The version.bump test: scripts/bump-version.sh on a copy of the files that state the version
# leaves all of them saying the new one (checked as version.agree checks the repository) and
# CHANGELOG.md with the release's section.
# usage: run_bump_test.sh SOURCE_DIR WORK_DIR
set -euo pipefail
source_dir=$1
work=$2
rm -rf "$work"
for f in CMakeLists.txt CHANGELOG.md engines/unity/package.json engines/godot/addons/unrealhaptics/plugin.cfg; do
  mkdir -p "$work/$(dirname "$f")"
  cp "$source_dir/$f" "$work/$f"
done
bash "$source_dir/scripts/bump-version.sh" 98.76.54 --root "$work"
grep -qE '^project\([A-Za-z]+ VERSION 98\.76\.54 ' "$work/CMakeLists.txt" || { echo "version.bump: CMakeLists.txt not bumped" >&2; exit 1; }
cmake -DUH_VERSION=98.76.54 -DUH_UNITY_MANIFEST="$work/engines/unity/package.json" \
  -DUH_GODOT_MANIFEST="$work/engines/godot/addons/unrealhaptics/plugin.cfg" -P "$source_dir/tests/version/check_versions.cmake"
grep -qE "^## \[98\.76\.54\] - [0-9]{4}-[0-9]{2}-[0-9]{2}$" "$work/CHANGELOG.md" || { echo "version.bump: no release section in CHANGELOG.md" >&2; exit 1; }
grep -q '^## \[Unreleased\]$' "$work/CHANGELOG.md" || { echo "version.bump: no Unreleased section left" >&2; exit 1; }
echo "version.bump: one command bumps every file that states the version"
