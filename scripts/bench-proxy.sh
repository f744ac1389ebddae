#!/usr/bin/env bash
# The 6-DOF proxy against the penalty path, in the same run (issue 23): a simulated hand pulls a
# 1 cm ball through plates of 1, 2 and 3 mm (packed with 10,000 spheres, flat and tilted 45 deg),
# slowly (5 cm in 1 s) and in one jerk (5 cm in 20 ms, 2.5 m/s), with 4 N and 8 N; then the
# collision step and haptic tick of the default session and the room of objects with each.
#   bash scripts/bench-proxy.sh [SECONDS]   (threaded runs of the default session and the room; default 10 s)
# Prints a Markdown table per part (docs/benchmarks.md, "The proxy"). UH=path/to/uh uses that binary.
# Not part of the tests: timings on a shared machine vary (the pop-through figures do not).
set -euo pipefail
source "$(dirname "$0")/common.sh"
seconds=${1:-10}
uh_release_cli
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

python3 - "$UH" "$uh_root" "$out" "$seconds" <<'EOF'
import json, math, subprocess, sys
uh, root, out, seconds = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4]

sys.path.insert(0, f"{root}/scripts")
from uh_mesh import write_mesh

def plate_obj(path, thickness_mm):
    h = thickness_mm / 20.0  # half thickness in cm units
    v = [(x, y, z) for z in (-h, h) for (x, y) in ((-3, -3), (3, -3), (3, 3), (-3, 3))]
    f = [(0, 2, 1), (0, 3, 2), (4, 5, 6), (4, 6, 7), (0, 1, 5), (0, 5, 4), (3, 7, 6), (3, 6, 2),
         (0, 4, 7), (0, 7, 3), (1, 2, 6), (1, 6, 5)]
    write_mesh(path, v, f, f"a {thickness_mm} mm plate", uh=uh)

base = json.load(open(f"{root}/scenes/thin_wall.json"))
print("| plate | tilt | hand | pull | path | ball ends (mm from the mid-plane) | largest force [N] |")
print("|---|---|---|---|---|---|---|")
for mm in (1, 2, 3):
    mesh = f"{out}/plate_{mm}.obj"
    plate_obj(mesh, mm)
    for tilt in (0, 45):
        for hand, duration in (("slow", 1.0), ("jerk", 0.02)):
            for pull in (4, 8):
                s = json.loads(json.dumps(base))
                s["objects"][0]["mesh"] = mesh
                half = math.radians(tilt) / 2
                s["objects"][0]["pose"]["rotation"] = [math.cos(half), math.sin(half), 0, 0]
                s["tool"]["mesh"] = f"{root}/assets/meshes/ball.obj"
                cfg = s["tool"]["device"]["config"]
                cfg["duration_s"] = duration
                cfg["hand_stiffness"] = pull / 0.035  # the pull when the ball rests on the plate
                normal = (0.0, -math.sin(2 * half), math.cos(2 * half))
                cells = []
                for path in ("on", "off"):
                    name = f"{out}/s_{mm}_{tilt}_{hand}_{pull}.json"
                    json.dump(s, open(name, "w"))
                    trace = f"{out}/t.csv"
                    r = json.loads(subprocess.run([uh, "run", name, "--json", "--stepped", "--proxy", path,
                                                   "--trace", trace],
                                                  check=True, capture_output=True, text=True).stdout)
                    if path == "on":
                        p = r["force"]["proxy"]["position"]
                    else:
                        last = open(trace).read().strip().splitlines()[-1].split(",")
                        p = [float(last[2]), float(last[3]), float(last[4])]
                    height = sum(a * b for a, b in zip(p, normal)) * 1e3
                    cells.append((height, r["force"]["max_n"]))
                for label, (height, force) in zip(("proxy", "penalty"), cells):
                    side = "holds" if height > mm / 2 else "**through**"
                    print(f"| {mm} mm | {tilt} deg | {hand} | {pull} N | {label} | {height:+.1f} ({side}) | {force:.2f} |")

print()
print("| session | path | collision rate median / min [Hz] | collision step median / p99 [us] | haptic tick p99 [us] | proxy solve p50 / p99 [us] | constraints (most) |")
print("|---|---|---|---|---|---|---|")
for label, scene in (("default (bunny sweep)", []), ("room of objects", [f"{root}/scenes/museum_room.json"])):
    for path in ("off", "on"):
        r = json.loads(subprocess.run([uh, "run", *scene, "--json", "--seconds", seconds, "--proxy", path],
                                      check=True, capture_output=True, text=True).stdout)
        c, h = r["collision"]["step_us"], r["haptic"]["tick_us"]
        p = r["force"]["proxy"]
        solve = f"{p['solve_us']['p50']:.1f} / {p['solve_us']['p99']:.1f}" if p else "-"
        most = str(p["max_constraints"]) if p else f"{r['collision'].get('max_pairs', '-')} pairs"
        rate = r["collision"]["rate_hz"]
        print(f"| {label} | {'proxy' if path == 'on' else 'penalty'} | {rate['median']:.0f} / {rate['min']:.0f} | "
              f"{c['median']:.0f} / {c['p99']:.0f} | "
              f"{h['p99']:.1f} | {solve} | {most} |")
EOF
