"""Sessions from Python: the default scene, a scene built through calls, threads, the context manager."""
import json
import pathlib
import subprocess
import threading
import time

import numpy as np
import pytest

import unrealhaptics as uh
from conftest import ASSETS, CUBE_TRIANGLES, CUBE_VERTICES, small_scene


def test_version_and_api():
    assert isinstance(uh.__version__, str) and uh.__version__.count(".") == 2
    assert uh.api_version == 2


def test_default_session_stepped_reads_contact_and_force():
    with uh.Session.open() as s:  # the default scene (bunny sweep)
        assert s.object_names == ["bunny"]
        report = s.run_stepped(3.0, 4)
        st = s.state()
        events = s.events()
    assert report["mode"] == "stepped" and report["haptic"]["ticks"] == 3000
    assert report["contact"]["ticks"] > 0
    assert st.haptic_ticks == 3000
    for name, shape in (("tool_position", (3,)), ("tool_orientation", (4,)), ("force", (3,)), ("torque", (3,))):
        value = getattr(st, name)
        assert isinstance(value, np.ndarray) and value.shape == shape and value.dtype == np.float64
    assert abs(np.linalg.norm(st.tool_orientation) - 1.0) < 1e-9
    assert np.linalg.norm(st.force) <= report["force"]["max_n"] + 1e-12
    begins = [e for e in events if e.kind == "begin"]
    # through the proxy, the default, which rests on the surface: its rows in contact, no overlap volume
    assert begins and all(e.object == 0 and e.volume == 0 and e.pairs > 0 for e in begins)


def test_threaded_session_polls_state_and_stop_returns_the_report(scene):
    with uh.Session.open(scene) as s:
        s.start()
        max_force, max_pairs, ticks, begins = 0.0, 0, [], 0
        end = time.monotonic() + 1.2
        while time.monotonic() < end:
            st = s.state()
            max_force = max(max_force, float(np.linalg.norm(st.force)))
            max_pairs = max(max_pairs, st.contact_pairs)
            assert st.buttons == 0  # the scene's scripted device presses none
            ticks.append(st.haptic_ticks)
            begins += sum(e.kind == "begin" for e in s.events())
            assert not s.ended_by_itself  # nothing faults here
            time.sleep(0.002)
        report = s.stop()
        assert not s.ended_by_itself  # stopped, not ended by itself
        assert s.stop() == report  # idempotent: the same report
        after = s.state()
    assert ticks == sorted(ticks) and ticks[-1] > 300
    assert 0.1 < max_force <= 6.0 + 1e-9
    assert max_pairs > 0 and begins >= 1
    assert np.linalg.norm(after.force) == 0.0  # the device got zero at stop
    assert report["mode"] == "threaded"
    assert report["force"]["max_n"] >= max_force - 1e-9
    assert set(report) == {"scene", "mode", "seconds", "device", "haptic", "collision", "force", "contact", "energy",
                           "stopped_early", "tools"}


def test_report_is_the_uh_run_json_object(scene):
    """stop() gives the same object, key for key, that `uh run --json` prints."""
    with uh.Session.open(scene) as s:
        report = s.run_stepped(0.2, 4)
    uh_program = pathlib.Path(uh.__file__).resolve().parents[1] / "apps" / "uh" / "uh"  # the same build
    assert uh_program.exists(), "build the uh program with the module"
    printed = json.loads(subprocess.run([str(uh_program), "run", "--stepped", "--seconds", "0.2", "--json"],
                                        check=True, capture_output=True, text=True).stdout)

    def keys(d, prefix=""):
        return {prefix + k for k in d} | {x for k, v in d.items() if isinstance(v, dict) for x in keys(v, prefix + k + ".")}
    assert keys(report) == keys(printed)


def test_leaving_the_block_stops_and_closes_even_on_error(scene):
    with pytest.raises(ZeroDivisionError):
        with uh.Session.open(scene) as s:
            s.start()
            1 / 0
    with pytest.raises(uh.UhError) as error:
        s.state()
    assert error.value.status == "UH_ERROR_STALE_HANDLE"
    s.close()  # twice: nothing


def test_several_sessions_at_once():
    a, b = uh.Session.open(small_scene()), uh.Session.open(small_scene())
    a.start()
    b.start()
    time.sleep(0.8)
    ra, rb = a.stop(), b.stop()
    a.close()
    b.close()
    assert ra["contact"]["ticks"] > 0 and rb["contact"]["ticks"] > 0


def test_long_calls_release_the_gil():
    """A stepped run holds no GIL: this thread keeps running Python while it works."""
    s = uh.Session.open()  # the default scene: 10,000 spheres each, about a second of work
    worker = threading.Thread(target=s.run_stepped, args=(3.0, 1))
    worker.start()
    time.sleep(0.05)
    still_inside = worker.is_alive()  # this thread woke up while the worker was in the C call
    worker.join()
    s.close()
    assert still_inside


def test_moving_an_object_moves_the_contact(scene):
    """The bunny moved 20 cm away while the session runs: no more contact."""
    with uh.Session.open(scene) as s:
        s.set_object_pose(0, (0.2, 0, 0), (1, 0, 0, 0))
        report = s.run_stepped(1.0, 4)
    assert report["contact"]["ticks"] == 0
    with pytest.raises(uh.UhError, match="no object 5"):
        uh.Session.open(small_scene()).set_object_pose(5, (0, 0, 0), (1, 0, 0, 0))


def test_bad_input_raises_with_a_message(scene):
    with pytest.raises(uh.UhError, match="missing.json") as error:
        uh.Session.open("missing.json")
    assert error.value.status == "UH_ERROR_FILE"  # each kind of failure has its status
    with pytest.raises(uh.UhError, match="exactly one"):
        scene.add_object("x", mesh="a.obj", ist="b.ist")
    with pytest.raises(uh.UhError, match="start"):
        scene.set_tool(vertices=CUBE_VERTICES, triangles=CUBE_TRIANGLES, spheres=50, device="sim-line",
                       config={"start": {"x": 1}})
    with pytest.raises(TypeError, match="unexpected keyword"):
        scene.set_tool(meshh="x")
    # each force law has its own stiffness, in its own unit: the other one's is refused
    with pytest.raises(ValueError, match="paper law"):
        scene.set_tool(vertices=CUBE_VERTICES, triangles=CUBE_TRIANGLES, spheres=50, force_scale=8e6)
    with pytest.raises(ValueError, match="gradient law"):
        scene.set_tool(vertices=CUBE_VERTICES, triangles=CUBE_TRIANGLES, spheres=50, law="paper", stiffness=1e4)
    with pytest.raises(ValueError, match="'gradient' or 'paper'"):
        scene.set_tool(vertices=CUBE_VERTICES, triangles=CUBE_TRIANGLES, spheres=50, law="volume")
    with pytest.raises(ValueError):
        uh.Session.open(scene).set_object_pose(0, (0, 0), (1, 0, 0, 0))


def test_two_tools_each_with_its_state(tmp_path):
    assets = pathlib.Path(__file__).resolve().parents[2] / "assets" / "meshes"
    tool = {"mesh": str(assets / "stylus.obj"), "meters_per_unit": 0.01, "spheres": 150,
            "force": {"mode": "3dof", "stiffness": 1.6e4, "max_force_n": 6.0}}
    scene = {"name": "two-python",
             "objects": [{"name": "bunny", "mesh": str(assets / "bunny_npm_3674.obj"), "meters_per_unit": 0.01,
                          "spheres": 600, "pose": {"rotation": [0.70710678, 0.70710678, 0, 0]}},
                         {"name": "ball", "mesh": str(assets / "ball.obj"), "meters_per_unit": 0.03, "spheres": 200,
                          "pose": {"position": [0.15, 0, 0.03]}}],
             "tools": [dict(tool, name="left", device={"driver": "sim-line",
                                                       "config": {"start": [0, 0, 0.1], "end": [0, 0, 0.045]}}),
                       dict(tool, name="right", device={"driver": "sim-line",
                                                        "config": {"start": [0.15, 0, 0.1], "end": [0.15, 0, 0.048]}})]}
    path = tmp_path / "two.json"
    path.write_text(json.dumps(scene))
    with uh.Session.open(str(path)) as s:
        assert s.tool_names == ["left", "right"]
        report = s.run_stepped(1.0, 4)
        left, right, first = s.state(0), s.state(1), s.state()
        with pytest.raises(uh.UhError, match="there is no tool 2"):
            s.state(2)
    assert [t["tool"] for t in report["tools"]] == ["left", "right"]
    assert all(t["contact"]["ticks"] > 0 for t in report["tools"])
    assert right.haptic_ticks == 1000 and abs(right.handle_position[0] - 0.15) < 1e-9
    assert first.haptic_ticks == left.haptic_ticks and abs(left.handle_position[0]) < 1e-9


def test_tools_added_through_calls_each_name_their_contacts():
    scene = small_scene()
    scene.add_object("ball", mesh=ASSETS / "ball.obj", spheres=200, meters_per_unit=0.03, position=(0.15, 0, 0.03))
    with pytest.raises(uh.UhError, match="a tool named 'stylus' already"):
        scene.add_tool(name="stylus", mesh=ASSETS / "stylus.obj", spheres=150, meters_per_unit=0.01)
    index = scene.add_tool(name="right", mesh=ASSETS / "stylus.obj", spheres=150, meters_per_unit=0.01, mode="3dof",
                           stiffness=1.6e4, max_force_n=4.0, config={"start": [0.15, 0, 0.1], "end": [0.15, 0, 0.048]})
    assert index == 1 and scene.tool_count == 2
    with uh.Session.open(scene) as s:
        assert s.tool_names == ["stylus", "right"]
        s.run_stepped(1.0, 4)
        events = s.events()
    begins = {(e.tool, e.object) for e in events if e.kind == "begin"}
    assert begins == {(0, 0), (1, 1)}  # the left stylus meets the bunny, the right one the ball
    scene.remove_tool("right")
    assert scene.tool_count == 1


def test_the_proxy_is_chosen_per_session_and_keeps_the_tool_on_the_surface(scene):
    """proxy=False: the tool is at the handle, inside the bunny at the press's deepest; proxy=True: on the surface
    above it, with contact events from its constraints; the handle's position is in the state either way."""
    held = {}
    for proxy in (False, True):
        with uh.Session.open(scene, proxy=proxy) as s:
            report = s.run_stepped(0.5, 4)
            st = s.state()
            events = s.events()
        assert isinstance(st.handle_position, np.ndarray) and st.handle_position.shape == (3,)
        assert abs(st.handle_position[2] - 0.045) < 1e-3
        assert report["force"]["max_n"] > 0.5
        assert any(e.kind == "begin" and e.pairs > 0 for e in events)
        held[proxy] = st.tool_position[2] - st.handle_position[2]
    assert held[False] == 0.0
    assert held[True] > 0.001
    with pytest.raises(TypeError, match="proxy is None"):
        uh.Session.open(scene, proxy="yes")
