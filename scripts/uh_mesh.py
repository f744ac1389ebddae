"""Writes a generated mesh through `uh mesh convert`, the project's one mesh writer: the mesh is
checked (closed, 2-manifold, outward) and written as every reader of meshes here sees it.

    from uh_mesh import write_mesh
    write_mesh("assets/meshes/torus.obj", verts, faces, "a torus", uh="build/main/apps/uh/uh")

`uh` defaults to $UH, else the Release build scripts/common.sh's uh_release_cli makes (build/main).
Coordinates are rounded to 6 decimals, as the committed meshes were written.
"""
import json
import os
import subprocess
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def uh_program(uh=None):
    uh = uh or os.environ.get("UH") or os.path.join(ROOT, "build/main/apps/uh/uh")
    if not os.access(uh, os.X_OK):
        raise SystemExit(f"{uh}: no uh program; build one (source scripts/common.sh; uh_release_cli) or set UH")
    return uh


def write_mesh(path, verts, faces, comment="", uh=None):
    mesh = {"vertices": [round(c, 6) for v in verts for c in v], "triangles": [i for f in faces for i in f]}
    with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
        json.dump(mesh, f)
    try:
        subprocess.run([uh_program(uh), "mesh", "convert", f.name, "-o", path, "--comment", comment],
                       check=True, stdout=subprocess.DEVNULL)
    finally:
        os.unlink(f.name)
