#include "uh/exploration/explore_scene.hpp"

#include <algorithm>
#include <memory>
#include <utility>

#include <fmt/format.h>

#include "explorer_device.hpp"
#include "plan.hpp"
#include "uh/haptico/device_registry.hpp"

namespace uh::exploration {
namespace {

using controllers::HapticSession;
using controllers::Scene;
using controllers::SceneObject;
using controllers::SessionOptions;

// The scene the hand explores `object` in: the object alone with the scene's first tool on the
// explorer's device, in the device frame = world, both shapes' trees preloaded from the cache (the
// planner reads them before the session exists, and the session takes them as loaded).
// The session's creation from it is open_explorer_session's.
Result<Scene> preload_object_scene(const Scene& scene, const SceneObject& object, const SessionOptions& so) {
  Scene alone = scene;
  alone.objects = {object};
  alone.watch = {object.name};
  alone.tools.resize(1);  // the first tool explores
  alone.tool().device = {.driver = "explorer", .config = {}};
  alone.tool().workspace = {};  // the device frame is the world frame
  auto object_tree = controllers::load_shape_tree(object.shape, so.cache_dir, so.build_progress);
  if (!object_tree)
    return Error{fmt::format("{}: object '{}': {}", scene.source, object.name, object_tree.error().message)};
  auto tool_tree = controllers::load_shape_tree(scene.tool().shape, so.cache_dir, so.build_progress);
  if (!tool_tree)
    return Error{fmt::format("{}: tool '{}': {}", scene.source, scene.tool().name, tool_tree.error().message)};
  alone.tool().shape.tree = tool_tree->tree;  // loaded once
  alone.tool().shape.coverage = tool_tree->coverage;
  alone.objects[0].shape.tree = object_tree->tree;
  alone.objects[0].shape.coverage = object_tree->coverage;
  return alone;
}

// A session on `alone` (preload_object_scene) whose device is `device`: handed over through a
// registry whose "explorer" driver gives it to one session only
Result<std::unique_ptr<HapticSession>> open_explorer_session(const Scene& alone, const SessionOptions& so,
                                                              std::unique_ptr<ExplorerDevice> device) {
  auto holder = std::make_shared<std::unique_ptr<haptico::HapticDevice>>(std::move(device));
  haptico::DeviceRegistry registry;
  if (auto r = registry.register_driver(
          "explorer",
          [holder](const haptico::DeviceConfig&) -> Result<std::unique_ptr<haptico::HapticDevice>> {
            if (!*holder) return Error{"the exploration's hand is used by one session only"};
            return std::move(*holder);
          });
      !r)
    return r.error();
  return HapticSession::create(alone, so, registry);
}

// The object of `alone` explored: the plan, the hand, the session run in simulated time, the trace
Result<ObjectExploration> explore_object(const Scene& scene, const Scene& alone, const ExploreOptions& options,
                                         const SessionOptions& so) {
  const SceneObject& object = alone.objects[0];
  auto plan = plan_exploration(*object.shape.tree, object.pose, *alone.tool().shape.tree, options);
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
  auto session = open_explorer_session(alone, so, std::move(device));
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
    auto alone = preload_object_scene(scene, object, so);
    if (!alone) return alone.error();
    auto explored = explore_object(scene, *alone, options, so);
    if (!explored) return explored.error();
    out.push_back(std::move(*explored));
  }
  if (!found) return no_such_object(scene, object_name);
  return out;
}

}  // namespace uh::exploration
