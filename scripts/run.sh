#!/usr/bin/env bash
# The main job: installs what is missing, builds in Release and runs the default haptic session.
# Extra arguments are passed to `uh run` (e.g. --seconds 20 --json).
set -euo pipefail
source "$(dirname "$0")/common.sh"
bash "$uh_root/scripts/install-deps.sh"
echo "== build (Release) =="
uh_build build/main uh_cli -- -DCMAKE_BUILD_TYPE=Release -DUH_BUILD_TESTS=OFF -DUH_BUILD_BENCHMARKS=OFF
echo "== uh run =="
"$uh_root/build/main/apps/uh/uh" run "$@"
