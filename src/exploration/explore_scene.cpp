#include "uh/exploration/explore_scene.hpp"

#include <algorithm>
#include <memory>
#include <utility>

#include <fmt/format.h>

#include "explorer_device.hpp"
#include "plan.hpp"
#include "uh/collette/ist_cache.hpp"
#include "uh/controllers/session_model.hpp"
#include "uh/forcecomp/virtual_coupling.hpp"

namespace uh::exploration {
namespace {

using controllers::HapticSession;
using controllers::Scene;
using controllers::SceneObject;
using controllers::SessionModel;
using controllers::SessionOptions;

// The scene the hand explores `object` in, compiled once: the object alone with the scene's first
// tool on the explorer's device, in the device frame = world, with the session's overrides. The
// model holds both shapes' trees (the planner reads them before the session exists) and the
// object's mesh surface, which the proxy rests on as in any session: a packed face reads flat, not
// as the packing's grain. A mesh's own facets are felt as they are: a round object meant to feel
// smooth needs faces that meet at a degree or two (assets/meshes/ball_fine.obj).
Result<std::shared_ptr<const SessionModel>> compile_object_scene(const Scene& scene, const SceneObject& object,
                                                                 const SessionOptions& so) {
  Scene alone = scene;
  alone.objects = {object};
  alone.watch = {object.name};
  alone.tools.resize(1);  // the first tool explores
  alone.tool().device = {.driver = "explorer", .config = {}};
  alone.tool().workspace = {};  // the device frame is the world frame
  collette::IstCache cache(so.cache_dir);
  return controllers::compile(controllers::with_session_options(alone, so), cache,
                              {.progress = so.build_progress});
}

// The object of `model` explored: the plan, the hand, the session run in simulated time, the trace
Result<ObjectExploration> explore_object(const Scene& scene, const std::shared_ptr<const SessionModel>& model,
                                         const ExploreOptions& options, const SessionOptions& so) {
  const Scene& alone = model->scene;
  const SceneObject& object = alone.objects[0];
  const double surface_gap_m = model->objects[0].surface ? model->objects[0].surface_gap_m : 0.0;
  auto plan = plan_exploration(*model->objects[0].tree, object.pose, *model->tools[0].tree, options, surface_gap_m);
  if (!plan) return Error{fmt::format("{}: object '{}': {}", scene.source, object.name, plan.error().message)};
  const double haptic_hz = *so.haptic_hz;
  const auto capacity = static_cast<std::size_t>(options.max_seconds * haptic_hz) + 16;
  // the smallest force limit of the session's chain (haptico::ForceLimiter): the hand's, the
  // tool's, the safety limit
  const double force_limit_n =
      std::min({kExplorerMaxForceN, alone.tool().force.max_force_n, alone.safety_limits.max_force_n});
  auto device = std::make_unique<ExplorerDevice>(haptico::SimDeviceOptions{.rate_hz = haptic_hz,
                                                                           .max_force_n = kExplorerMaxForceN,
                                                                           .dof_actuated = 3,
                                                                           .workspace_half_extents = {10.0, 10.0, 10.0}},
                                                 options, *plan, press_stop_force_n(options, force_limit_n), capacity);
  ExplorerDevice* explorer = device.get();
  std::vector<std::unique_ptr<haptico::HapticDevice>> hands;
  hands.push_back(std::move(device));
  auto session = HapticSession::create(model, std::move(hands), {.raise_priority = so.raise_priority});
  if (!session) return session.error();
  explorer->set_session(session->get());
  if (auto ran = (*session)->run_stepped(options.max_seconds, options.ticks_per_collision_step); !ran)
    return ran.error();
  if (!explorer->touched())
    return Error{fmt::format("{}: object '{}': the tool never touched it on its way in", scene.source, object.name)};
  ObjectExploration result;
  result.object = object.name;
  result.trace.samples = std::move(explorer->trace());
  result.trace.options = options;
  result.trace.force_limit_n = force_limit_n;
  result.trace.stroke_axes[0] = plan->axes[0];
  result.trace.stroke_axes[1] = plan->axes[1];
  result.trace.axis_point = plan->axis_point;
  if (alone.force.proxy.enabled)
    result.rendered_stiffness_limit_n_per_m = forcecomp::VirtualCoupling(alone.force.coupling).stiffness();
  result.work_on_hand_j = (*session)->report().work_on_hand_j;
  result.simulated_s = (*session)->report().seconds;
  result.haptic_ticks = (*session)->report().haptic_ticks;
  result.estimate = estimate_material(result.trace);
  return result;
}

Error no_such_object(const Scene& scene, const std::string& object_name) {
  std::string names;
  for (const auto& o : scene.objects) names += fmt::format("{}'{}'", names.empty() ? "" : ", ", o.name);
  return Error{fmt::format("{}: no object is named '{}' (the scene has {})", scene.source, object_name, names)};
}

}  // namespace

Result<std::vector<ObjectExploration>> explore_scene(const Scene& scene, const std::string& object_name,
                                                     const ExploreOptions& options,
                                                     const SessionOptions& session_options) {
  std::vector<ObjectExploration> out;
  SessionOptions so = session_options;
  so.cache_dir = session_options.cache_dir.empty() ? controllers::default_cache_dir() : session_options.cache_dir;
  const double haptic_hz = options.haptic_hz.value_or(session_options.haptic_hz.value_or(scene.haptic_hz));
  if (!(haptic_hz >= 1.0 && haptic_hz <= 10000.0))
    return Error{fmt::format("{}: haptic rate {} Hz is outside [1, 10000]", scene.source, haptic_hz)};
  so.haptic_hz = haptic_hz;
  so.collision_hz = haptic_hz / options.ticks_per_collision_step;
  bool found = object_name.empty();
  for (const SceneObject& object : scene.objects) {
    if (!object_name.empty() && object.name != object_name) continue;
    found = true;
    auto model = compile_object_scene(scene, object, so);
    if (!model) return model.error();
    auto explored = explore_object(scene, *model, options, so);
    if (!explored) return explored.error();
    out.push_back(std::move(*explored));
  }
  if (!found) return no_such_object(scene, object_name);
  return out;
}

}  // namespace uh::exploration
