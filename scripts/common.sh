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
    launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
    # paths relative to the checkout, so that another clone of the same sources reuses the cache
    # (builds with debug information still hash their directory: their paths stay true)
    export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$uh_root}"
  fi
  cmake -S "$uh_root" -B "$uh_root/$dir" -G Ninja "${launcher[@]}" "$@" >/dev/null
  local target_args=()
  for t in "${targets[@]}"; do target_args+=(--target "$t"); done
  cmake --build "$uh_root/$dir" -j "$uh_jobs" "${target_args[@]}"
}
