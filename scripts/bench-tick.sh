#!/usr/bin/env bash
# The O(1) haptic tick's figures (issue 11, item 1): the local wrench model against the exact
# re-evaluation of every held pair, measured in the same run of this script, along the shipped
# sweeps at 1, 4 and 10 kHz haptic with the collision thread at 1 kHz, 250 Hz and 100 Hz.
#   bash scripts/bench-tick.sh [SECONDS]     (threaded runs of the default session; default 10 s)
# Stepped runs (simulated time, deterministic) give the force error and the steps; threaded runs
# give tick times and missed deadlines. UH=path/to/uh uses that binary instead of building one.
# Not part of the tests: timings on a shared machine vary.
set -euo pipefail
source "$(dirname "$0")/common.sh"
seconds=${1:-10}
uh_release_cli
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
run() { uh_bench_run "$@"; }
descent="$uh_root/scenes/bunny_descent.json"
sweep="$uh_root/scenes/bunny_sweep.json"
press="$uh_root/scenes/bunny_hand_press.json"

# force error and steps: stepped, every haptic/collision rate pair, model (checked), exact, held
for scene in descent sweep; do
  file=$descent; extra=()
  [ "$scene" = sweep ] && { file=$sweep; extra=(--seconds 4); }
  for hz in 1000 4000 10000; do
    for chz in 1000 250 100; do
      n=$((hz / chz))
      common=("$file" "${extra[@]}" --stepped --haptic-hz "$hz" --ticks-per-collision "$n")
      run "err_${scene}_${hz}_${chz}_model" "${common[@]}" --check-model --trace "$out/err_${scene}_${hz}_${chz}_model.csv"
      run "err_${scene}_${hz}_${chz}_exact" "${common[@]}" --exact-tick --trace "$out/err_${scene}_${hz}_${chz}_exact.csv"
      run "err_${scene}_${hz}_${chz}_held" "${common[@]}" --held-forces --trace "$out/err_${scene}_${hz}_${chz}_held.csv"
    done
  done
done
# tick times: the default session (~17,000 pairs), threaded
for hz in 1000 4000 10000; do
  for chz in 1000 250 100; do
    run "tick_${hz}_${chz}_model" --seconds "$seconds" --haptic-hz "$hz" --collision-hz "$chz"
    run "tick_${hz}_${chz}_exact" --seconds "$seconds" --haptic-hz "$hz" --collision-hz "$chz" --exact-tick
  done
done
# passivity with the reacting hand
for hz in 1000 4000; do
  for mode in model exact; do
    flag=(); [ "$mode" = exact ] && flag=(--exact-tick)
    run "press_${hz}_${mode}_stepped" "$press" --stepped --haptic-hz "$hz" --ticks-per-collision $((hz / 1000)) "${flag[@]}"
    run "press_${hz}_${mode}_threaded" "$press" --haptic-hz "$hz" "${flag[@]}"
  done
done

python3 - "$out" <<'PY'
import csv, json, math, sys, os
d = sys.argv[1]
j = {n[:-5]: json.load(open(os.path.join(d, n))) for n in os.listdir(d) if n.endswith(".json")}
f = lambda r: r["force"]

def forces(name):
    """The force the controller asked for, per tick (before the limit chain), from the trace."""
    with open(os.path.join(d, name + ".csv")) as t:
        return [(float(r["tick_time_s"]), (float(r["req_fx"]), float(r["req_fy"]), float(r["req_fz"]))) for r in csv.DictReader(t)]

def steps(name):
    """Tick-to-tick steps after the first 50 ms (bunny_sweep starts the tool inside the bunny: its
    first frame is a step in every mode) and before the last tick (the run's end sends zero)."""
    fs = forces(name)
    return [(t, math.dist(a, b)) for (t, a), (_, b) in zip(fs[1:-1], fs[:-2]) if t >= 0.05]
for scene, label in [("descent", "bunny_descent (stylus 6 cm down into the bunny, 3 s)"),
                     ("sweep", "bunny_sweep, the default session (raster through deep contact, first 4 s)")]:
    print(f"\n{label}, stepped (simulated time): the model's force against the exact re-evaluation of every held pair")
    print()
    print("| haptic / collision | max contact force [N] | model error RMS / max [N] | largest step: model / exact / held forces [N] | step the model adds to exact's [N] | held-forces step / model step | max force / model step |")
    print("|---|---|---|---|---|---|---|")
    for hz in (1000, 4000, 10000):
        for chz in (1000, 250, 100):
            key = f"err_{scene}_{hz}_{chz}"
            m = j[key + "_model"]
            sm, se, sh = (steps(f"{key}_{k}") for k in ("model", "exact", "held"))
            ms, es, hs = (max(s for _, s in x) for x in (sm, se, sh))
            # the device is scripted (it does not react): model and exact runs follow the same path,
            # so their traces compare tick by tick
            fm, fe = forces(key + "_model"), forces(key + "_exact")
            added = max(math.dist([a - b for a, b in zip(fm[i][1], fm[i - 1][1])], [a - b for a, b in zip(fe[i][1], fe[i - 1][1])])
                        for i in range(1, min(len(fm), len(fe)) - 1) if fm[i][0] >= 0.05)
            top = f(j[key + "_exact"])["max_n"]
            print(f"| {hz / 1000:g} kHz / {chz} Hz | {top:.2f} | {f(m)['model']['error_rms_n']:.4f} / {f(m)['model']['error_max_n']:.4f} | "
                  f"{ms:.4f} / {es:.4f} / {hs:.4f} | {added:.4f} | {hs / ms:.1f}x | {top / ms:.0f}x |")
print("\nThe default session (10,000-sphere stylus in the 10,000-sphere bunny), threaded, haptic tick duration and deadlines")
print()
print("| haptic / collision | pairs (max) | tick p50 / p99 / max, model [us] | tick p50 / p99 / max, exact [us] | p99 ratio exact / model | missed deadlines model / exact | SCHED_FIFO |")
print("|---|---|---|---|---|---|---|")
for hz in (1000, 4000, 10000):
    for chz in (1000, 250, 100):
        m, e = j[f"tick_{hz}_{chz}_model"], j[f"tick_{hz}_{chz}_exact"]
        tm, te = m["haptic"]["tick_us"], e["haptic"]["tick_us"]
        print(f"| {hz / 1000:g} kHz / {chz} Hz | {m['collision']['max_pairs']} | {tm['p50']:.1f} / {tm['p99']:.1f} / {tm['max']:.0f} | "
              f"{te['p50']:.1f} / {te['p99']:.1f} / {te['max']:.0f} | {te['p99'] / tm['p99'] if tm['p99'] > 0 else float('inf'):.0f}x | "
              f"{m['haptic']['missed_deadlines']} / {e['haptic']['missed_deadlines']} | {'yes' if m['haptic']['priority_raised'] else 'no'} |")
print("\nPassivity with the reacting hand (bunny_hand_press: presses 5 cm into the bunny and back, twice, virtual coupling): energy into the hand [J] (<= 0: passive)")
print()
print("| run | model | exact |")
print("|---|---|---|")
for hz in (1000, 4000):
    for how in ("stepped", "threaded"):
        m, e = j[f"press_{hz}_model_{how}"], j[f"press_{hz}_exact_{how}"]
        print(f"| {hz / 1000:g} kHz, {how} | {m['energy']['work_on_hand_j']:.5f} | {e['energy']['work_on_hand_j']:.5f} |")
PY
