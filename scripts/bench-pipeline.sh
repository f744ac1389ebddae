#!/usr/bin/env bash
# The haptic pipeline's figures (issue "Haptico, ForceComp and the haptic pipeline"): runs `uh run`
# on the repository's scenes and prints a Markdown table for docs/benchmarks.md.
#   bash scripts/bench-pipeline.sh [SECONDS]      (default 60 s for the long runs)
# Needs a Release build of uh (scripts/run.sh or scripts/test.sh makes one). Not part of the tests:
# timings on a shared machine vary; run it on a quiet one.
set -euo pipefail
source "$(dirname "$0")/common.sh"
seconds=${1:-60}
uh_release_cli
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
run() { uh_bench_run "$@"; }
run deep1k --seconds "$seconds"
run deep4k --seconds "$seconds" --haptic-hz 4000
run descent_multi "$uh_root/scenes/bunny_descent.json" --collision-hz 250
run descent_held "$uh_root/scenes/bunny_descent.json" --collision-hz 250 --held-forces
run descent4k_multi "$uh_root/scenes/bunny_descent.json" --collision-hz 250 --haptic-hz 4000
run descent4k_held "$uh_root/scenes/bunny_descent.json" --collision-hz 250 --haptic-hz 4000 --held-forces
run sdescent_multi "$uh_root/scenes/bunny_descent.json" --stepped --ticks-per-collision 4
run sdescent_held "$uh_root/scenes/bunny_descent.json" --stepped --ticks-per-collision 4 --held-forces
run sdescent4k_multi "$uh_root/scenes/bunny_descent.json" --stepped --haptic-hz 4000 --ticks-per-collision 16
run sdescent4k_held "$uh_root/scenes/bunny_descent.json" --stepped --haptic-hz 4000 --ticks-per-collision 16 --held-forces
run circle_stepped "$uh_root/scenes/bunny_coupling_circle.json" --stepped --ticks-per-collision 1
run circle_threaded "$uh_root/scenes/bunny_coupling_circle.json"
press="$uh_root/scenes/bunny_hand_press.json"
stiff="$uh_root/scenes/bunny_hand_press_too_stiff.json"
run press1k_stepped "$press" --stepped --ticks-per-collision 1
run press4k_stepped "$press" --stepped --haptic-hz 4000 --ticks-per-collision 4
run press1k_threaded "$press"
run press4k_threaded "$press" --haptic-hz 4000
run stiff1k_stepped "$stiff" --stepped --ticks-per-collision 1
run stiff4k_stepped "$stiff" --stepped --haptic-hz 4000 --ticks-per-collision 4

python3 - "$out" <<'PY'
import json, sys, os
d = sys.argv[1]
j = {n[:-5]: json.load(open(os.path.join(d, n))) for n in os.listdir(d)}
print("| run | haptic rate [Hz] | missed | jitter p50 / p99 / max [us] | collision median / min [Hz] | query median / p99 / max [us] | max pairs | max force [N] | clamped |")
print("|---|---|---|---|---|---|---|---|---|")
for name, label in [("deep1k", "default scene, 1 kHz"), ("deep4k", "default scene, 4 kHz")]:
    r = j[name]; h = r["haptic"]; c = r["collision"]; f = r["force"]
    print(f"| {label}, {r['seconds']:.0f} s | {h['rate_hz']:.1f} | {h['missed_deadlines']} | "
          f"{h['jitter_us']['p50']:.1f} / {h['jitter_us']['p99']:.1f} / {h['jitter_us']['max']:.1f} | "
          f"{c['rate_hz']['median']:.0f} / {c['rate_hz']['min']:.0f} | {c['query_us']['median']:.0f} / {c['query_us']['p99']:.0f} / {c['query_us']['max']:.0f} | "
          f"{c['max_pairs']} | {f['max_n']:.2f} | {f['clamped']} |")
print()
print("| force continuity, collision at 250 Hz (bunny_descent) | threaded, haptic 1 kHz | threaded, haptic 4 kHz | stepped, 1 kHz | stepped, 4 kHz |")
print("|---|---|---|---|---|")
cols = [("descent_multi", "descent_held"), ("descent4k_multi", "descent4k_held"), ("sdescent_multi", "sdescent_held"),
        ("sdescent4k_multi", "sdescent4k_held")]
ms = [j[m]["force"]["max_step_n"] for m, _ in cols]
hs = [j[h]["force"]["max_step_n"] for _, h in cols]
print("| largest tick-to-tick step, held forces [N] | " + " | ".join(f"{h:.5f}" for h in hs) + " |")
print("| largest tick-to-tick step, multi-rate re-evaluation [N] | " + " | ".join(f"{m:.5f}" for m in ms) + " |")
print("| ratio held / multi-rate | " + " | ".join(f"{h / m:.1f}x" if m > 0 else "inf" for m, h in zip(ms, hs)) + " |")
print()
print("| passivity, closed circle through the surface with the virtual coupling | energy into the hand [J] | max force [N] |")
print("|---|---|---|")
for name, label in [("circle_stepped", "stepped (simulated time, collision every tick)"), ("circle_threaded", "threaded")]:
    r = j[name]
    print(f"| {label} | {r['energy']['work_on_hand_j']:.5f} | {r['force']['max_n']:.2f} |")
print()
print("| passivity with a hand that reacts (sim-hand presses 5 cm into the bunny and back, twice) | 1 kHz: energy into the hand [J] | max force [N] | 4 kHz: energy into the hand [J] | max force [N] |")
print("|---|---|---|---|---|")
for (a, b), label in [(("press1k_stepped", "press4k_stepped"), "bunny_hand_press, stepped"),
                      (("press1k_threaded", "press4k_threaded"), "bunny_hand_press, threaded"),
                      (("stiff1k_stepped", "stiff4k_stepped"), "bunny_hand_press_too_stiff (coupling 9x the real bound), stepped")]:
    ra, rb = j[a], j[b]
    print(f"| {label} | {ra['energy']['work_on_hand_j']:.5f} | {ra['force']['max_n']:.2f} | "
          f"{rb['energy']['work_on_hand_j']:.5f} | {rb['force']['max_n']:.2f} |")
PY
