"""Inner Sphere Trees from Python: load, build, query."""
import numpy as np
import pytest

import unrealhaptics as uh
from conftest import ASSETS, CUBE_TRIANGLES, CUBE_VERTICES


@pytest.fixture(scope="module")
def cube():
    return uh.Ist.from_arrays(np.array(CUBE_VERTICES, dtype=float), CUBE_TRIANGLES, spheres=400, meters_per_unit=0.01)


def test_self_overlap_is_the_packing_volume(cube):
    """At the identity every leaf meets itself and no other (the packing does not overlap)."""
    r = cube.query(cube, position=(0, 0, 0), orientation=(1, 0, 0, 0))
    assert abs(cube.mesh_volume - 8e-6) < 1e-12  # (2 cm)^3
    assert r.volume == pytest.approx(cube.coverage * cube.mesh_volume, rel=1e-4)
    assert r.volume_estimate == pytest.approx(cube.mesh_volume / cube.coverage, rel=1e-4)
    assert r.pair_count >= cube.leaf_count and r.distance == 0.0


def test_direction_pushes_b_out_and_apart_gives_a_distance(cube):
    r = cube.query(cube, position=(0.005, 0, 0), orientation=(2, 0, 0, 0))  # any scale: normalised
    assert r.volume > 0 and isinstance(r.direction, np.ndarray) and r.direction.shape == (3,)
    assert r.direction[0] > 0.9
    apart = cube.query(cube, position=(0.1, 0, 0))
    assert apart.volume == 0 and apart.pair_count == 0 and 0.07 < apart.distance < 0.1


def test_build_save_load_query_as_in_the_issue(tmp_path, cube):
    b = uh.Ist.build(str(ASSETS / "stylus.obj"), spheres=300, meters_per_unit=0.01)
    path = tmp_path / "stylus.ist"
    b.save(str(path))
    a = uh.Ist.load(str(path))
    assert a.leaf_count == b.leaf_count
    pose = dict(position=(0.0, 0.0, 0.01), orientation=(0.9238795, 0.3826834, 0, 0))
    r1, r2 = a.query(cube, **pose), b.query(cube, **pose)
    assert r1.volume == r2.volume and r1.pair_count == r2.pair_count and r1.volume > 0


def test_bad_input(cube):
    with pytest.raises(uh.UhError, match="missing.ist"):
        uh.Ist.load("missing.ist")
    with pytest.raises(uh.UhError, match="not closed"):
        uh.Ist.from_arrays(np.array(CUBE_VERTICES, dtype=float), CUBE_TRIANGLES[:10], spheres=100)
    with pytest.raises(ValueError, match="shape"):
        uh.Ist.from_arrays(np.zeros((8, 2)), CUBE_TRIANGLES, spheres=100)
    with pytest.raises(uh.UhError, match="orientation"):
        cube.query(cube, position=(0, 0, 0), orientation=(0, 0, 0, 0))
