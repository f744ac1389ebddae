// Cost of reading a running session's newest state: HapticSession::state() in C++ against
// uh_session_poll() through the C API (handle lookup, per-session checks, exception barrier,
// copy into uh_state), on the same kind of session running the same scene in the same program.
// The Python figure comes from bench/capi/python_state_bench.py (same scene, same machine).

#include <benchmark/benchmark.h>

#include <cstdlib>
#include <memory>

#include "uh/controllers/haptic_session.hpp"
#include "uh/uh.h"

namespace {

// the small scene of the tests: 600 + 150 spheres, a stylus going in and out (scenes/ has no
// scene this small; a large scene would only load the machine while state() is measured)
// zero on failure
uh_scene_id small_scene() {
  uh_scene_id scene{0};
  if (uh_scene_create("bench", &scene) != UH_OK) return uh_scene_id{0};
  uh_object_def bunny = uh_default_object_def();
  bunny.name = "bunny";
  bunny.shape.mesh_path = UH_ASSET_DIR "/meshes/bunny_npm_3674.obj";
  bunny.shape.spheres = 600;
  bunny.shape.meters_per_unit = 0.01;
  bunny.orientation[0] = bunny.orientation[1] = 0.70710678;
  uh_tool_def tool = uh_default_tool_def();
  tool.shape.mesh_path = UH_ASSET_DIR "/meshes/stylus.obj";
  tool.shape.spheres = 150;
  tool.shape.meters_per_unit = 0.01;
  tool.stiffness = 1.6e4;
  tool.max_force_n = 6.0;
  tool.device_config_json =
      R"({"start": [0, 0, 0.10], "end": [0, 0, 0.045], "duration_s": 0.5, "bounce": true, "dof_actuated": 6, "max_force_n": 6})";
  if (uh_scene_add_object(scene, &bunny, nullptr) != UH_OK || uh_scene_set_tool(scene, &tool) != UH_OK)
    return uh_scene_id{0};
  return scene;
}

void BM_CApiPoll(benchmark::State& state) {
  const uh_scene_id scene = small_scene();
  uh_session_id s{0};
  if (scene.bits == 0 || uh_session_create(scene, nullptr, &s) != UH_OK || uh_session_start(s) != UH_OK) {
    state.SkipWithError(uh_last_error());
    return;
  }
  uh_state st{};
  st.struct_size = sizeof st;
  for (auto _ : state) {
    benchmark::DoNotOptimize(uh_session_poll(s, &st));
    benchmark::ClobberMemory();
  }
  state.counters["haptic_ticks"] = static_cast<double>(st.haptic_ticks);
  uh_session_destroy(s);
  uh_scene_destroy(scene);
}
BENCHMARK(BM_CApiPoll)->UseRealTime();

// the peer: the C++ call the C API wraps, on a session of the same scene (its JSON form)
void BM_CppState(benchmark::State& state) {
  using namespace uh::controllers;
  auto scene = parse_scene(R"({
    "objects": [{"name": "bunny", "mesh": "meshes/bunny_npm_3674.obj", "meters_per_unit": 0.01, "spheres": 600,
                 "pose": {"position": [0, 0, 0], "rotation": [0.70710678, 0.70710678, 0, 0]}}],
    "tool": {"name": "tool", "mesh": "meshes/stylus.obj", "meters_per_unit": 0.01, "spheres": 150,
             "force": {"stiffness": 1.6e4, "max_force_n": 6.0},
             "device": {"driver": "sim-line", "config": {"start": [0, 0, 0.10], "end": [0, 0, 0.045], "duration_s": 0.5,
                                                          "bounce": true, "dof_actuated": 6, "max_force_n": 6}}}})",
                           "bench", UH_ASSET_DIR);
  if (!scene) {
    state.SkipWithError(scene.error().message.c_str());
    return;
  }
  auto session = HapticSession::create(*scene);
  if (!session || !(*session)->start()) {
    state.SkipWithError("the session did not start");
    return;
  }
  SessionState st;
  for (auto _ : state) {
    st = (*session)->state();
    benchmark::DoNotOptimize(st);
  }
  state.counters["haptic_ticks"] = static_cast<double>(st.haptic_ticks);
  const uh::Status stopped = (*session)->stop();
  (void)stopped;
}
BENCHMARK(BM_CppState)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
