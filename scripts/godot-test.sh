#!/usr/bin/env bash
# The Godot addon's headless tests: the demo project (engines/godot/demo, its addon linked from
# engines/godot/addons) runs engines/godot/tests/run_tests.gd in godot3-server against the uh
# program of a build, on a free loopback port. Godot's HOME and XDG folders are kept inside the
# build folder. A GDScript error does not end Godot, so the run is bounded by a timeout, longer than
# the test's own waits (the soft demo's session may take 2 min to start, packing its block into a
# cold cache on a loaded machine), so that a check rather than the timeout says what failed; a uh serve
# the test started is ended by its process id if it outlived Godot.
# usage: scripts/godot-test.sh BUILD_DIR     (prints "N passed, N failed"; exit status 1 on failure)
#   UH_PROGRAM (environment): another uh than the build's; UH_GODOT_PROJECT: another copy of the demo
#   project (the packaged addon's test, tests/package/run_engine_packages_test.sh)
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "${1:?usage: godot-test.sh BUILD_DIR}" && pwd)
uh="${UH_PROGRAM:-$build/apps/uh/uh}"
project="${UH_GODOT_PROJECT:-$root/engines/godot/demo}"
[ -x "$uh" ] || { echo "godot-test: $uh is missing (build the uh program first)"; exit 1; }
command -v godot3-server >/dev/null || { echo "godot-test: godot3-server is missing (scripts/install-deps.sh)"; exit 1; }
work="$build/godot"
rm -rf "$work"
mkdir -p "$work/home" "$work/config" "$work/data" "$work/cache"
port=$(/usr/bin/python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
log="$work/godot.log"
HOME="$work/home" XDG_CONFIG_HOME="$work/config" XDG_DATA_HOME="$work/data" XDG_CACHE_HOME="$work/cache" \
  LANG=en_US.UTF-8 LC_ALL= UH_PROGRAM="$uh" UH_TEST_PORT="$port" UH_CACHE_DIR="${UH_CACHE_DIR:-$build/test-cache}" \
  timeout -k 5 360 godot3-server --path "$project" -s "$root/engines/godot/tests/run_tests.gd" \
  >"$log" 2>&1
code=$?
cat "$log"
# the uh serve processes the test started: those it printed, and one it started on this run's port
# before it could print it (Godot timed out waiting for its session)
pids=$( (grep -oE "^uh serve pid [0-9]+" "$log" | grep -oE "[0-9]+$"; \
         pgrep -f -- "uh serve --host 127.0.0.1 --port $port\$") | sort -u)
for pid in $pids; do
  # (an exited child whose parent is gone may stay a zombie where nothing reaps it: not running)
  if [ "$pid" -gt 0 ] && [ "$(ps -o comm= -p "$pid" 2>/dev/null)" = "uh" ] && \
     [[ "$(ps -o stat= -p "$pid" 2>/dev/null)" != Z* ]]; then
    echo "godot-test: the uh serve the test started (pid $pid) outlived Godot; ending it"
    kill -TERM "$pid"
  fi
done
if ! grep -qE "^[0-9]+ passed, [0-9]+ failed$" "$log"; then
  echo "godot-test: no result line (Godot exited with $code; a GDScript error or the timeout)"
  echo "0 passed, 1 failed"
  exit 1
fi
[ "$code" -eq 0 ]
