"""Shared fixtures: the committed meshes, a cache for packed meshes, the small test scene."""
import os
import pathlib

import pytest

import unrealhaptics as uh

ASSETS = pathlib.Path(__file__).resolve().parents[2] / "assets" / "meshes"

# packed meshes are cached next to the built module, shared by test runs
os.environ.setdefault("UH_CACHE_DIR", str(pathlib.Path(uh.__file__).resolve().parent / "cache"))


def small_scene():
    """A 10 cm bunny (600 spheres) and a stylus (150) going down into it and back every second."""
    scene = uh.Scene.create("small-python")
    scene.add_object("bunny", mesh=ASSETS / "bunny_npm_3674.obj", spheres=600, meters_per_unit=0.01,
                     orientation=(0.70710678, 0.70710678, 0, 0))
    scene.set_tool(name="stylus", mesh=ASSETS / "stylus.obj", spheres=150, meters_per_unit=0.01,
                   stiffness=1.6e4, damping=1.0, center_of_mass=(0, 0, 0.025), max_force_n=6.0, max_torque_nm=0.3,
                   device="sim-line",
                   config={"start": [0, 0, 0.10], "end": [0, 0, 0.045], "duration_s": 0.5, "bounce": True,
                           "dof_actuated": 6, "max_force_n": 6})
    return scene


@pytest.fixture
def scene():
    return small_scene()


# a closed cube of side 2 (mesh units), counter-clockwise from outside
CUBE_VERTICES = [[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1], [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]]
CUBE_TRIANGLES = [[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4],
                  [1, 2, 6], [1, 6, 5], [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7]]
