#!/usr/bin/env bash
# Can this machine hold a 10 kHz haptic loop? (issue 11: "10 kHz in the default deep-contact
# session with no missed deadline in 60 s under SCHED_FIFO".) Three runs of the same length, one
# after the other in this script, so that they see the same machine:
#   1. cyclictest (Debian's rt-tests), the operating system's own reference: a SCHED_FIFO thread
#      waking every 100 us; how often it wakes more than a period (100 us) late;
#   2. `uh run --haptic-hz 10000` on a scene where the tool touches nothing: our loop and an
#      almost empty tick, so its missed deadlines are the machine's, not the force rendering's;
#   3. `uh run --haptic-hz 10000` in the default deep-contact session (about 17,000 held pairs).
# If 2 misses about as often as 3, the misses come from the machine (a virtual machine's stolen
# time, other processes), not from the tick's work; cyclictest shows the same from outside.
#   bash scripts/bench-latency.sh [SECONDS]     (default 60; needs root or CAP_SYS_NICE for SCHED_FIFO)
# UH=path/to/uh uses that binary instead of building one. Not part of the tests.
set -euo pipefail
source "$(dirname "$0")/common.sh"
seconds=${1:-60}
command -v cyclictest >/dev/null || { echo "bench-latency: cyclictest not found (Debian package rt-tests)" >&2; exit 1; }
uh_release_cli
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

# the idle scene: the deep-contact scene's objects, the stylus held 40 cm above them
python3 - "$uh_root/scenes/bunny_descent.json" "$out/idle_scene.json" <<'PY'
import json, os, sys
source, target = sys.argv[1], sys.argv[2]
scene = json.load(open(source))
base = os.path.dirname(os.path.abspath(source))
for entry in scene["objects"] + [scene["tool"]]:
    entry["mesh"] = os.path.normpath(os.path.join(base, entry["mesh"]))
config = scene["tool"]["device"]["config"]
config["start"] = [0.0, 0.0, 0.5]
config["end"] = [0.0, 0.0, 0.5]
scene["name"] = "idle-10khz"
scene["description"] = "bench-latency.sh: the stylus never touches the bunny"
json.dump(scene, open(target, "w"), indent=2)
PY

echo "running: cyclictest at 100 us for $seconds s" >&2
cyclictest -m -p 90 -i 100 -D "$seconds" -q -h 5000 >"$out/cyclictest.txt"
uh_bench_run idle "$out/idle_scene.json" --seconds "$seconds" --haptic-hz 10000
uh_bench_run deep --seconds "$seconds" --haptic-hz 10000

python3 - "$out" "$seconds" <<'PY'
import json, os, sys
d, seconds = sys.argv[1], float(sys.argv[2])
late = total = 0
maximum = overflows = 0
for line in open(os.path.join(d, "cyclictest.txt")):
    if line.startswith("# Total:"):
        total = int(line.split()[2])
    elif line.startswith("# Max Latencies:"):
        maximum = int(line.split()[3])
    elif line.startswith("# Histogram Overflows:"):
        overflows = int(line.split()[3])
    elif line[:1].isdigit():
        us, count = (int(x) for x in line.split()[:2])
        if us > 100:
            late += count
late += overflows
runs = {n: json.load(open(os.path.join(d, n + ".json"))) for n in ("idle", "deep")}
print(f"{seconds:.0f} s each, load average {os.getloadavg()[0]:.1f} at the end")
print("| run | wake-ups or ticks | more than a period (100 us) late | worst [us] | tick p99 / max [us] | SCHED_FIFO |")
print("|---|---|---|---|---|---|")
print(f"| cyclictest -p 90 -i 100 | {total} | {late} | {maximum} | - | yes |")
for name, label in (("idle", "uh run, tool touching nothing"), ("deep", "uh run, default deep contact")):
    h = runs[name]["haptic"]
    print(f"| {label} | {h['ticks']} | {h['missed_deadlines']} | {h['jitter_us']['max']:.0f} | "
          f"{h['tick_us']['p99']:.1f} / {h['tick_us']['max']:.0f} | {'yes' if h['priority_raised'] else 'no'} |")
PY
