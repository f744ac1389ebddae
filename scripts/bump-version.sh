#!/usr/bin/env bash
# A release's version in one command: project(VERSION) in CMakeLists.txt, the Unity manifest
# (engines/unity/package.json) and the Godot addon's plugin.cfg (the engines read those two from the
# repository as they are, so they carry it too), and CHANGELOG.md's Unreleased section becomes the
# release's. The test version.agree fails when one of them says another version.
# usage: bump-version.sh X.Y.Z [--root DIR]   (--root: another checkout, e.g. a copy in a test)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
version=${1:-}
[ "${2:-}" = --root ] && root=$3
[[ $version =~ ^[0-9]+\.[0-9]+\.[0-9]+$ ]] || { echo "bump-version: give the version as X.Y.Z" >&2; exit 2; }
changelog="$root/CHANGELOG.md"
grep -q '^## \[Unreleased\]' "$changelog" || { echo "bump-version: $changelog has no '## [Unreleased]' section" >&2; exit 1; }
! grep -q "^## \[$version\]" "$changelog" || { echo "bump-version: $changelog has $version already" >&2; exit 1; }

sed -i -E "s/^(project\([A-Za-z]+ VERSION )[0-9]+\.[0-9]+\.[0-9]+/\1$version/" "$root/CMakeLists.txt"
sed -i -E "0,/\"version\": \"[^\"]*\"/s//\"version\": \"$version\"/" "$root/engines/unity/package.json"
sed -i -E "s/^version=\"[^\"]*\"/version=\"$version\"/" "$root/engines/godot/addons/unrealhaptics/plugin.cfg"
# what was unreleased is this version's now; a new, empty Unreleased section above it
sed -i "s/^## \[Unreleased\].*/## [Unreleased]\n\n## [$version] - $(date -u +%F)/" "$changelog"
echo "bump-version: $version in CMakeLists.txt, engines/unity/package.json, plugin.cfg and CHANGELOG.md"
