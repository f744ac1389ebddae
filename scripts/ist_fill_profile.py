#!/usr/bin/env python3
"""How full a packing is under its top face: the fill fraction phi(d) at depth d below the highest
sphere top, over a square around the vertical axis, and phi / coverage (the share of the gradient
law's stiffness a tool pressing to depth d feels: the slope of force against depth is
2 pi r k phi(d) / coverage for a ball of radius r on a flat face, docs/exploration.md).

    python3 scripts/ist_fill_profile.py PACKING.ist [--half-width UNITS] [--depths D1,D2,...]
                                        [--ball RADIUS --at X,Y]

With --ball, also the exact force on a ball of that radius [mesh units] pressed to each depth below
the top at (X, Y): the gradient law's sum over the packing's spheres (each pushes with
pi a^2 along the centre line, a the radius of the circle where the ball and the sphere meet; the
lens formula, not the library's kernel) over the coverage, against the solid's pi (2 r d - d^2),
with k = 1: the share of the stiffness a press to that depth reads there.

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
    if args.ball:
        ball_x, ball_y = (float(v) for v in args.at.split(","))
        print(f"ball of radius {args.ball:g} at ({ball_x:g}, {ball_y:g}): force / solid's force")
        for depth in (float(d) for d in args.depths.split(",")):
            force = ball_force(spheres, args.ball, (ball_x, ball_y, top + args.ball - depth)) / coverage
            solid = math.pi * (2 * args.ball * depth - depth * depth)
            print(f"{depth:<10.4g} {force / solid:.3f}")


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
