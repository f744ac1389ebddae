#!/usr/bin/env python3
"""How full a packing is under its top face: the fill fraction phi(d) at depth d below the highest
sphere top, over a square around the vertical axis, and phi / coverage (the share of the gradient
law's stiffness a tool pressing to depth d feels: the slope of force against depth is
2 pi r k phi(d) / coverage for a ball of radius r on a flat face, docs/exploration.md).

    python3 scripts/ist_fill_profile.py PACKING.ist [--half-width UNITS] [--depths D1,D2,...]
                                        [--ball RADIUS --at X,Y]
                                        [--ball RADIUS --press DEPTH [--sites N --spread UNITS]]

With --ball, also the exact force on a ball of that radius [mesh units] pressed to each depth below
the top at (X, Y): the gradient law's sum over the packing's spheres (each pushes with
pi a^2 along the centre line, a the radius of the circle where the ball and the sphere meet; the
lens formula, not the library's kernel) over the coverage, against the solid's pi (2 r d - d^2),
with k = 1: the share of the stiffness a press to that depth reads there.

With --press, what `uh explore`'s press estimator reads from that exact force (docs/exploration.md,
"The estimators"), over an N x N grid of sites (--sites, --spread: half side of the grid): each
press goes DEPTH past the ball's first contact with a sphere, the parabola through the force at
depths from 15 % to 95 % of that is read for its slope where it reaches zero force, and the slope
over the solid's 2 pi r (k = 1) is printed per site, with their mean, median and range.

Reads the .ist layout of src/collette/ist_file.cpp (header of 128 bytes, nodes of 32, leaves of
16: x, y, z, radius as little-endian floats, mesh units). Standard library only.
"""
import argparse
import math
import struct

HEADER_BYTES, NODE_BYTES, LEAF_BYTES = 128, 32, 16
OFF_NODES, OFF_LEAVES, OFF_COVERAGE = 16, 20, 48


def read_leaves(path):
    data = open(path, "rb").read()
    if data[:5] != b"UHIST":
        raise SystemExit(f"{path}: not a .ist sphere-tree file")
    nodes, leaves = struct.unpack_from("<II", data, OFF_NODES)
    (coverage,) = struct.unpack_from("<d", data, OFF_COVERAGE)
    first = HEADER_BYTES + nodes * NODE_BYTES
    spheres = [struct.unpack_from("<ffff", data, first + LEAF_BYTES * i) for i in range(leaves)]
    return spheres, coverage


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("ist")
    parser.add_argument("--half-width", type=float, default=2.5, help="half side of the square [mesh units]")
    parser.add_argument("--depths", default="0.005,0.01,0.02,0.03,0.05,0.075,0.1,0.15,0.2,0.25",
                        help="depths below the top [mesh units]")
    parser.add_argument("--ball", type=float, help="radius of a ball pressed at --at [mesh units]")
    parser.add_argument("--at", default="0,0", help="where the ball presses: X,Y [mesh units]")
    parser.add_argument("--press", type=float, help="press depth past the first contact [mesh units]")
    parser.add_argument("--sites", type=int, default=5, help="--press: sites per side of the grid")
    parser.add_argument("--spread", type=float, default=1.5, help="--press: half side of the grid [mesh units]")
    args = parser.parse_args()
    spheres, coverage = read_leaves(args.ist)
    top = max(z + r for _, _, z, r in spheres)
    w = args.half_width
    print(f"{len(spheres)} spheres, coverage {coverage:.4f}, top at z = {top:.6g}")
    print("depth      phi     phi/coverage")
    for depth in (float(d) for d in args.depths.split(",")):
        level = top - depth
        area = sum(math.pi * (r * r - (z - level) ** 2)
                   for x, y, z, r in spheres if abs(x) < w and abs(y) < w and abs(z - level) < r)
        phi = area / (2 * w) ** 2
        print(f"{depth:<10.4g} {phi:.3f}   {phi / coverage:.3f}")
    if args.ball and args.press:
        print_press_readings(spheres, coverage, args)
    elif args.ball:
        ball_x, ball_y = (float(v) for v in args.at.split(","))
        print(f"ball of radius {args.ball:g} at ({ball_x:g}, {ball_y:g}): force / solid's force")
        for depth in (float(d) for d in args.depths.split(",")):
            force = ball_force(spheres, args.ball, (ball_x, ball_y, top + args.ball - depth)) / coverage
            solid = math.pi * (2 * args.ball * depth - depth * depth)
            print(f"{depth:<10.4g} {force / solid:.3f}")


def print_press_readings(spheres, coverage, args):
    radius, depth, n = args.ball, args.press, args.sites
    readings = []
    for i in range(n):
        for j in range(n):
            x = -args.spread + 2 * args.spread * i / (n - 1) if n > 1 else 0.0
            y = -args.spread + 2 * args.spread * j / (n - 1) if n > 1 else 0.0
            near = [s for s in spheres if (s[0] - x) ** 2 + (s[1] - y) ** 2 < (radius + s[3]) ** 2]
            # the ball's centre height at first contact: where it touches the highest sphere
            contact = max(z + math.sqrt((radius + r) ** 2 - (sx - x) ** 2 - (sy - y) ** 2) for sx, sy, z, r in near)
            ds = [depth * (0.15 + 0.8 * q / 39) for q in range(40)]
            fs = [ball_force(near, radius, (x, y, contact - d)) / coverage for d in ds]
            readings.append(touch_slope(ds, fs) / (2 * math.pi * radius))
            print(f"({x:+.3f}, {y:+.3f})  {readings[-1]:.3f}")
    ordered = sorted(readings)
    print(f"press reading / 2 pi r k over {len(readings)} sites: mean {sum(readings) / len(readings):.3f}, "
          f"median {ordered[len(ordered) // 2]:.3f}, range {ordered[0]:.3f}..{ordered[-1]:.3f}")


def touch_slope(ds, fs):
    """The least-squares parabola's slope where it reaches zero force below the data."""
    mean = sum(ds) / len(ds)
    us = [d - mean for d in ds]
    m = [[sum(u ** (a + b) for u in us) for b in range(3)] + [sum(u ** a * f for u, f in zip(us, fs))]
         for a in range(3)]
    for col in range(3):  # Gauss-Jordan
        pivot = max(range(col, 3), key=lambda r: abs(m[r][col]))
        m[col], m[pivot] = m[pivot], m[col]
        for r in range(3):
            if r != col:
                q = m[r][col] / m[col][col]
                m[r] = [a - q * b for a, b in zip(m[r], m[col])]
    c0, c1, c2 = (m[k][3] / m[k][k] for k in range(3))
    line = sum(u * f for u, f in zip(us, fs)) / sum(u * u for u in us)  # the fallback, as the estimator's
    if abs(c2) < 1e-12 * abs(c1):
        root = -c0 / c1
    else:
        disc = c1 * c1 - 4 * c2 * c0
        below = [u for u in ((-c1 + sgn * math.sqrt(max(disc, 0.0))) / (2 * c2) for sgn in (1, -1)) if u <= min(us)]
        if disc < 0 or not below:
            return line
        root = max(below)
    slope = c1 + 2 * c2 * root
    return slope if slope > 0 else line


def ball_force(spheres, radius, centre):
    """The gradient law's force on a ball (k = 1) along +z, summed over the spheres it meets."""
    cx, cy, cz = centre
    push = 0.0
    for x, y, z, r in spheres:
        dx, dy, dz = cx - x, cy - y, cz - z
        dist2 = dx * dx + dy * dy + dz * dz
        if dist2 >= (radius + r) ** 2 or dist2 == 0.0:
            continue
        dist = math.sqrt(dist2)
        t = (dist2 + radius * radius - r * r) / (2 * dist)  # from the ball's centre to the circle's plane
        a2 = radius * radius - t * t
        if a2 > 0.0 and dist > abs(radius - r):
            push += math.pi * a2 * dz / dist
    return push


if __name__ == "__main__":
    main()
