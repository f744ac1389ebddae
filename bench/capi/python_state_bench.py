"""Cost of Session.state() from Python on a running session (the small scene of the tests), with
two peers measured in the same run: Session.events() with nothing queued (the smallest call that
crosses into libuh and back) and reading one attribute of a State (no call at all).

    PYTHONPATH=build/release/python /usr/bin/python3 bench/capi/python_state_bench.py
"""
import json
import pathlib
import statistics
import timeit

import unrealhaptics as uh

ASSETS = pathlib.Path(__file__).resolve().parents[2] / "assets" / "meshes"


def main():
    scene = uh.Scene.create("bench")
    scene.add_object("bunny", mesh=ASSETS / "bunny_npm_3674.obj", spheres=600, meters_per_unit=0.01,
                     orientation=(0.70710678, 0.70710678, 0, 0))
    scene.set_tool(mesh=ASSETS / "stylus.obj", spheres=150, meters_per_unit=0.01, stiffness=1.6e4, max_force_n=6.0,
                   device="sim-line", config={"start": [0, 0, 0.10], "end": [0, 0, 0.045], "duration_s": 0.5,
                                              "bounce": True, "dof_actuated": 6, "max_force_n": 6})
    results = {}
    with uh.Session.open(scene) as s:
        s.start()
        st = s.state()
        number = 20000
        for name, stmt in (("state", s.state), ("events (nothing queued)", s.events),
                           ("st.force (attribute of a State)", lambda: st.force)):
            runs = timeit.repeat(stmt, number=number, repeat=7)
            results[name] = {"median_us": statistics.median(runs) / number * 1e6, "min_us": min(runs) / number * 1e6}
        s.stop()
    print(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
