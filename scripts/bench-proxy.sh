#!/usr/bin/env bash
# The 6-DOF proxy against the penalty path, in the same run (issue 23): a simulated hand pulls a
# 1 cm ball through plates of 1, 2 and 3 mm (packed with 10,000 spheres, flat and tilted 45 deg),
# slowly (5 cm in 1 s) and in one jerk (5 cm in 20 ms, 2.5 m/s), with 4 N and 8 N; then the
# collision step and haptic tick of the default session and the room of objects with each; and
# 6-DOF: the torque of a rod pressed by its end against r x F, a peg slid into a hole.
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

def box_obj(path, size, centre, comment):
    """A box of `size` [cm] about `centre` [cm]."""
    v = [(centre[0] + x * size[0] / 2, centre[1] + y * size[1] / 2, centre[2] + z * size[2] / 2)
         for z in (-1, 1) for (x, y) in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    f = [(0, 2, 1), (0, 3, 2), (4, 5, 6), (4, 6, 7), (0, 1, 5), (0, 5, 4), (3, 7, 6), (3, 6, 2),
         (0, 4, 7), (0, 7, 3), (1, 2, 6), (1, 6, 5)]
    write_mesh(path, v, f, comment, uh=uh)

def plate_obj(path, thickness_mm):
    box_obj(path, (6, 6, thickness_mm / 10.0), (0, 0, 0), f"a {thickness_mm} mm plate")

def plate_with_hole_obj(path, outer_half, hole_half, thickness):
    """A plate [cm] with a square hole through it, its top face at z = 0 (genus one)."""
    corners = ((-1, -1), (1, -1), (1, 1), (-1, 1))
    v = [(x * half, y * half, z) for z in (0.0, -thickness) for half in (outer_half, hole_half) for (x, y) in corners]
    f = []
    for k in range(4):
        n = (k + 1) % 4
        for a, b, c, d in ((k, n, 4 + n, 4 + k), (8 + k, 12 + k, 12 + n, 8 + n), (8 + k, 8 + n, n, k),
                           (12 + n, 12 + k, 4 + k, 4 + n)):
            f += [(a, b, c), (a, c, d)]
    write_mesh(path, v, f, "a plate with a square hole", uh=uh)

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

# Torques and a peg: a 4 x 1 x 1 cm rod tilted 10 deg about y pressed by its end (and flat) 1.5 mm
# into a slab's face, and a 1 x 1 x 4 cm peg lowered beside a 12 mm square hole in a 2 cm plate, slid
# over its edge at 2 cm/s to 0.5 mm past the far wall and pushed down through it at 2 cm/s
# (sim-replay, 6-DOF device, stepped). Torque error: the torque sent against r x F about the tool's
# centre, r the midpoint of the rod's lowest edge at the tool's pose (the proxy's, or the handle's).
def replay(path, rows):
    with open(path, "w") as f:
        f.write("time_s,x,y,z,qw,qx,qy,qz\n")
        for r in rows:
            f.write(",".join(f"{c:.6f}" for c in r) + "\n")

def six_dof_scene(name, obj, tool, spheres, csv, seconds):
    return {"name": name, "rates": {"haptic_hz": 1000, "collision_hz": 1000}, "seconds": seconds,
            "objects": [{"name": "object", "mesh": obj, "meters_per_unit": 0.01, "spheres": 10000}],
            "tool": {"name": "tool", "mesh": tool, "meters_per_unit": 0.01, "spheres": spheres,
                     "force": {"mode": "6dof", "law": "gradient", "stiffness": 20000.0, "damping": 2.0,
                               "max_force_n": 8.0, "max_torque_nm": 0.5},
                     "device": {"driver": "sim-replay", "config": {"file": csv, "dof_actuated": 6, "max_force_n": 8,
                                                                   "max_torque_nm": 0.5}}},
            "watch": ["object"]}

def run_traced(scene, path, seconds=None):
    name, trace = f"{out}/six.json", f"{out}/six.csv"
    json.dump(scene, open(name, "w"))
    extra = ["--seconds", str(seconds)] if seconds else []
    r = json.loads(subprocess.run([uh, "run", name, "--json", "--stepped", "--proxy", path, "--trace", trace, *extra],
                                  check=True, capture_output=True, text=True).stdout)
    rows = [[float(c) for c in line.split(",")] for line in open(trace).read().strip().splitlines()[1:]]
    return r, rows

def rotate(q, v):
    w, x, y, z = q
    u = (x, y, z)
    t = [2 * (u[1] * v[2] - u[2] * v[1]), 2 * (u[2] * v[0] - u[0] * v[2]), 2 * (u[0] * v[1] - u[1] * v[0])]
    return [v[i] + w * t[i] + (u[(i + 1) % 3] * t[(i + 2) % 3] - u[(i + 2) % 3] * t[(i + 1) % 3]) for i in range(3)]

def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]

slab, rod = f"{out}/slab.obj", f"{out}/rod.obj"
box_obj(slab, (10, 10, 2), (0, 0, -1), "a slab")
box_obj(rod, (4, 1, 1), (0, 0, 0), "a rod")
print()
print("| rod pressed 1.5 mm | path | force [N] | torque y [N m] | r x F y [N m] | torque error |")
print("|---|---|---|---|---|---|")
for label, tilt in (("by its end (10 deg)", math.radians(10)), ("flat, centred", 0.0)):
    q = (math.cos(tilt / 2), 0.0, math.sin(tilt / 2), 0.0)
    touch = 0.02 * math.sin(tilt) + 0.005 * math.cos(tilt)
    replay(f"{out}/rod.csv", [(0.0, 0, 0, 0.03, *q), (0.6, 0, 0, touch - 0.0015, *q), (1.5, 0, 0, touch - 0.0015, *q)])
    for path in ("on", "off"):
        r, rows = run_traced(six_dof_scene("rod", slab, rod, 2000, f"{out}/rod.csv", 1.5), path)
        force = [sum(row[23 + i] for row in rows[-100:]) / 100 for i in range(3)]
        torque = [sum(row[26 + i] for row in rows[-100:]) / 100 for i in range(3)]
        pose_q = r["force"]["proxy"]["rotation"] if path == "on" else q
        moment = cross(rotate(pose_q, (0.02, 0.0, -0.005)), force)
        err = math.dist(torque, moment) / math.hypot(*moment) if tilt else float("nan")
        # centred: the centre of pressure's distance from the centre, |torque| / |force|
        error = f"{100 * err:.1f} %" if tilt else f"{math.hypot(*torque) / math.hypot(*force) * 1e3:.2f} mm lever"
        expected = f"{moment[1]:+.4f}" if tilt else "0 (centred)"
        print(f"| {label} | {'proxy' if path == 'on' else 'penalty'} | {force[2]:.3f} | {torque[1]:+.4f} | "
              f"{expected} | {error} |")

plate = f"{out}/plate_hole.obj"
plate_with_hole_obj(plate, 3.0, 0.6, 2.0)
peg = f"{out}/peg.obj"
box_obj(peg, (1, 1, 4), (0, 0, 0), "a peg")
up = (1.0, 0.0, 0.0, 0.0)
replay(f"{out}/peg.csv", [(0.0, -0.015, 0, 0.04, *up), (0.44, -0.015, 0, 0.018, *up), (0.6, -0.015, 0, 0.018, *up),
                          (1.425, 0.0015, 0, 0.018, *up), (2.925, 0.0015, 0, -0.012, *up)])
print()
print("| peg into the hole | path | bottom at 2.0 s / 3.2 s [mm below the face] (the hand's: 13.5 / 32.0) | "
      "largest upward force in the hole [N] | largest torque [N m] |")
print("|---|---|---|---|---|")
for path in ("on", "off"):
    depths = []
    for secs in (2.0, 3.2):
        r, rows = run_traced(six_dof_scene("peg", plate, peg, 3000, f"{out}/peg.csv", 3.2), path, secs)
        bottom = (r["force"]["proxy"]["position"][2] if path == "on" else rows[-1][4]) - 0.02
        depths.append(-bottom * 1e3)
    inside = [row for row in rows if row[0] > 1.425 and row[4] - 0.02 < -0.002]
    print(f"| 10 mm peg, 12 mm hole | {'proxy' if path == 'on' else 'penalty'} | {depths[0]:.1f} / {depths[1]:.1f} | "
          f"{max(row[25] for row in inside):.2f} | {max(math.hypot(row[26], row[27], row[28]) for row in rows):.4f} |")

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
