"""A soft object from Python: scenes/soft_block.json's block pressed by its ball in a stepped run."""
import pathlib

import numpy as np
import pytest

import unrealhaptics as uh
from conftest import small_scene

SCENES = pathlib.Path(__file__).resolve().parents[2] / "scenes"


def test_deformed_vertices_of_the_soft_block_go_down_under_the_ball():
    with uh.Session.open(SCENES / "soft_block.json") as s:
        rest = s.deformed_vertices(0)
        triangles = s.soft_triangles(0)
        assert rest.dtype == np.float32 and rest.ndim == 2 and rest.shape[1] == 3 and len(rest) > 1000
        assert triangles.dtype == np.int32 and triangles.shape[1] == 3
        assert triangles.min() == 0 and triangles.max() == len(rest) - 1
        # block.obj (7 x 7 x 2 cm, top at z = 0) at rest
        assert np.allclose(rest.min(axis=0), [-0.035, -0.035, -0.02], atol=1e-6)
        assert np.allclose(rest.max(axis=0), [0.035, 0.035, 0.0], atol=1e-6)
        s.run_stepped(1.0, 1)  # the ball 6 mm into the top
        pressed = s.deformed_vertices(0)
    under = (np.abs(rest[:, 2]) < 1e-6) & (np.hypot(rest[:, 0], rest[:, 1]) < 0.004)
    assert under.sum() > 0
    drop = rest[under, 2] - pressed[under, 2]
    assert drop.min() > 2e-4 and drop.max() > 5e-4
    far = np.hypot(rest[:, 0], rest[:, 1]) > 0.03
    assert np.abs(pressed[far] - rest[far]).max() < drop.max()  # the dent is under the ball


def test_a_rigid_object_has_no_deformed_vertices():
    with uh.Session.open(small_scene()) as s:
        with pytest.raises(uh.UhError, match="'bunny' is rigid") as error:
            s.deformed_vertices(0)
        assert error.value.status == "UH_ERROR_INVALID_ARGUMENT"
