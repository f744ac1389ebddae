# Shared by run.sh and test.sh: configure and build one build directory.
# usage: uh_build DIR TARGETS... -- CMAKE_ARGS...
uh_root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
uh_jobs=$(nproc 2>/dev/null || echo 2)

uh_build() {
  local dir=$1; shift
  local targets=()
  while [ $# -gt 0 ] && [ "$1" != "--" ]; do targets+=("$1"); shift; done
  [ "${1:-}" = "--" ] && shift
  local launcher=()
  if command -v ccache >/dev/null 2>&1; then
    launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
    # Another clone of the same sources reuses the cache: ccache hashes paths relative to the
    # checkout, the objects hold source paths relative to it (-ffile-prefix-map, also in the
    # debug information, so builds with -g need not hash their directory either), and the tests'
    # absolute paths live in one generated source (tests/support/test_paths.hpp).
    export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$uh_root}"
    export CCACHE_NOHASHDIR=1
    launcher+=("-DCMAKE_CXX_FLAGS=-ffile-prefix-map=$uh_root/=" "-DCMAKE_C_FLAGS=-ffile-prefix-map=$uh_root/=")
  fi
  cmake -S "$uh_root" -B "$uh_root/$dir" -G Ninja "${launcher[@]}" "$@" >/dev/null
  local target_args=()
  for t in "${targets[@]}"; do target_args+=(--target "$t"); done
  cmake --build "$uh_root/$dir" -j "$uh_jobs" "${target_args[@]}"
}

# The Release `uh` the benchmark scripts run, in $UH: the one given there, else a build in build/main.
uh_release_cli() {
  if [ -z "${UH:-}" ]; then
    uh_build build/main uh_cli -- -DCMAKE_BUILD_TYPE=Release -DUH_BUILD_TESTS=OFF -DUH_BUILD_BENCHMARKS=OFF >/dev/null
    UH="$uh_root/build/main/apps/uh/uh"
  fi
}

# uh_bench_run NAME ARGS...: `uh run ARGS --json` into $out/NAME.json (for the scripts' tables).
uh_bench_run() {
  local name=$1; shift
  echo "running: uh run $*" >&2
  "$UH" run "$@" --json >"$out/$name.json"
}

# The release's version: project(VERSION) of the top-level CMakeLists.txt (docs/packaging.md).
uh_project_version() {
  sed -nE 's/^project\([A-Za-z]+ VERSION ([0-9]+\.[0-9]+\.[0-9]+).*/\1/p' "$uh_root/CMakeLists.txt"
}
