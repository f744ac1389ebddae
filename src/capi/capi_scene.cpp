// The C API's scenes: from a file, JSON text or calls (objects, tool, device, watched pairs, rates).

#include <algorithm>
#include <filesystem>
#include <vector>

#include "capi_support.hpp"
#include "uh/collette/ist_builder.hpp"

namespace uh::capi {
namespace {

uh_status add_scene(controllers::Scene scene, uh_scene** out) {
  auto box = std::make_shared<SceneBox>();
  box->scene = std::move(scene);
  const std::uintptr_t handle = scene_table().insert(std::move(box));
  if (handle == 0) return fail(UH_ERROR_FAILED, "too many scenes are open at once (about a million)");
  *out = as_handle<uh_scene>(handle);
  return UH_OK;
}

// The shape of a def: exactly one source; files must exist now; arrays are packed here.
Result<controllers::SceneShape> shape_from_def(const std::string& what, const uh_shape_def& def) {
  if (def.struct_size < sizeof(uh_shape_def))
    return Error{fmt::format("{}: shape.struct_size is {}, expected at least {}", what, def.struct_size,
                             sizeof(uh_shape_def))};
  const int sources = (def.mesh_path != nullptr) + (def.ist_path != nullptr) + (def.tree != nullptr) +
                      (def.vertices != nullptr || def.indices != nullptr);
  if (sources != 1)
    return Error{
        fmt::format("{}: give exactly one of shape.mesh_path, shape.ist_path, shape.tree or "
                    "shape.vertices with shape.indices (got {})",
                    what, sources)};
  if (def.spheres <= 0 || def.spheres > 2'000'000)
    return Error{fmt::format("{}: shape.spheres must be in [1, 2000000] (got {})", what, def.spheres)};
  if (!(def.meters_per_unit > 0.0) || !std::isfinite(def.meters_per_unit))
    return Error{
        fmt::format("{}: shape.meters_per_unit must be positive (got {})", what, def.meters_per_unit)};
  controllers::SceneShape shape{.spheres = def.spheres, .meters_per_unit = def.meters_per_unit};
  const auto existing_file = [&](const char* path, const char* field) -> Result<std::filesystem::path> {
    std::filesystem::path p = std::filesystem::absolute(path);
    if (!std::filesystem::exists(p))
      return Error{fmt::format("{}: shape.{}: file not found: {}", what, field, p.string())};
    return p;
  };
  if (def.mesh_path != nullptr) {
    auto p = existing_file(def.mesh_path, "mesh_path");
    if (!p) return p.error();
    shape.mesh = *p;
  } else if (def.ist_path != nullptr) {
    auto p = existing_file(def.ist_path, "ist_path");
    if (!p) return p.error();
    shape.ist = *p;
  } else if (def.tree != nullptr) {
    const auto box = tree_table().find(handle_value(def.tree));
    if (!box) return Error{fmt::format("{}: shape.tree is not an open tree handle", what)};
    shape.tree = box->tree;
    // 0 when unknown: the gradient law is then uncalibrated
    if (box->meta.coverage > 0.0 && box->meta.coverage <= 1.0) shape.coverage = box->meta.coverage;
  } else {
    uh_tree* tree = nullptr;
    const uh_tree_build_def build{.struct_size = sizeof(uh_tree_build_def),
                                  .spheres = def.spheres,
                                  .meters_per_unit = def.meters_per_unit};
    if (uh_tree_build_from_arrays(def.vertices, def.vertex_count, def.indices, def.triangle_count, &build,
                                  &tree) != UH_OK)
      return Error{fmt::format("{}: {}", what, uh_last_error())};
    const std::shared_ptr<TreeBox> built = tree_table().remove(handle_value(tree));
    if (!built) return Error{fmt::format("{}: the tree built from the arrays was lost", what)};
    shape.tree = built->tree;
    if (built->meta.coverage > 0.0 && built->meta.coverage <= 1.0) shape.coverage = built->meta.coverage;
  }
  return shape;
}

std::vector<controllers::SceneObject>::iterator find_object(controllers::Scene& scene,
                                                            const std::string& name) {
  return std::find_if(scene.objects.begin(), scene.objects.end(),
                      [&](const controllers::SceneObject& o) { return o.name == name; });
}

// The scene behind a handle and its object called `name`.
struct NamedObject {
  std::shared_ptr<SceneBox> box;
  std::vector<controllers::SceneObject>::iterator object;
};

uh_status find_named(const char* fn, const uh_scene* scene, const char* name, NamedObject& out) {
  if (name == nullptr) return null_argument(fn, "name");
  out.box = scene_table().find(handle_value(scene));
  if (!out.box) return stale(fn, "scene");
  out.object = find_object(out.box->scene, name);
  if (out.object == out.box->scene.objects.end())
    return fail(UH_ERROR_INVALID_ARGUMENT, fmt::format("{}: no object is named '{}'", fn, name));
  return UH_OK;
}

}  // namespace
}  // namespace uh::capi

using namespace uh;
using namespace uh::capi;

extern "C" {

uh_shape_def uh_default_shape_def(void) {
  return uh_shape_def{.struct_size = sizeof(uh_shape_def),
                      .mesh_path = nullptr,
                      .ist_path = nullptr,
                      .tree = nullptr,
                      .vertices = nullptr,
                      .vertex_count = 0,
                      .indices = nullptr,
                      .triangle_count = 0,
                      .spheres = 10000,
                      .meters_per_unit = 1.0};
}

uh_object_def uh_default_object_def(void) {
  return uh_object_def{.struct_size = sizeof(uh_object_def),
                       .name = nullptr,
                       .shape = uh_default_shape_def(),
                       .position = {0.0, 0.0, 0.0},
                       .orientation = {1.0, 0.0, 0.0, 0.0},
                       .watch = 1};
}

uh_tool_def uh_default_tool_def(void) {
  const forcecomp::ForceParams f{};
  return uh_tool_def{
      .struct_size = sizeof(uh_tool_def),
      .name = "tool",
      .shape = uh_default_shape_def(),
      .mode = UH_FORCE_6DOF,
      .law = UH_FORCE_LAW_GRADIENT,
      .stiffness = f.stiffness,
      .force_scale = f.force_scale,
      .damping = f.damping,
      .damping_full_volume = f.damping_full_volume,
      .mass_kg = f.mass_kg,
      .center_of_mass = {f.center_of_mass_body.x, f.center_of_mass_body.y, f.center_of_mass_body.z},
      .max_force_n = f.max_force_n,
      .max_torque_nm = f.max_torque_nm,
      .device_driver = "sim-line",
      .device_config_json = nullptr,
      .workspace_scale = 1.0,
      .workspace_offset = {0.0, 0.0, 0.0},
      .workspace_rotation = {1.0, 0.0, 0.0, 0.0}};
}

uh_status uh_scene_create(const char* name, uh_scene** out) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    if (out == nullptr) return null_argument(fn, "out");
    *out = nullptr;
    controllers::Scene scene;
    scene.name = name != nullptr ? name : "scene";
    scene.source = fmt::format("scene '{}'", scene.name);
    return add_scene(std::move(scene), out);
  });
}

uh_status uh_scene_load(const char* scene_path, uh_scene** out) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    if (out == nullptr) return null_argument(fn, "out");
    *out = nullptr;
    auto scene = scene_path != nullptr ? controllers::load_scene(scene_path)
                                       : controllers::default_scene(controllers::default_cache_dir());
    if (!scene) return fail(UH_ERROR_FAILED, scene.error().message);
    return add_scene(std::move(scene).value(), out);
  });
}

uh_status uh_scene_parse(const char* json_text, const char* base_dir, uh_scene** out) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    if (json_text == nullptr) return null_argument(fn, "json_text");
    if (out == nullptr) return null_argument(fn, "out");
    *out = nullptr;
    const std::filesystem::path base =
        base_dir != nullptr ? std::filesystem::path(base_dir) : std::filesystem::current_path();
    auto scene = controllers::parse_scene(json_text, "scene JSON", base);
    if (!scene) return fail(UH_ERROR_FAILED, scene.error().message);
    return add_scene(std::move(scene).value(), out);
  });
}

void uh_scene_free(uh_scene* scene) {
  const char* const fn = __func__;
  const uh_status ignored = guarded(fn, [&]() -> uh_status {
    scene_table().remove(handle_value(scene));
    return UH_OK;
  });
  (void)ignored;
}

uh_status uh_scene_add_object(uh_scene* scene, const uh_object_def* def, int32_t* out_index) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    if (auto s = check_struct(fn, "def", def); s != UH_OK) return s;
    const auto box = scene_table().find(handle_value(scene));
    if (!box) return stale(fn, "scene");
    if (def->name == nullptr || *def->name == '\0')
      return fail(UH_ERROR_INVALID_ARGUMENT, fmt::format("{}: def->name is empty", fn));
    controllers::Scene& sc = box->scene;
    if (find_object(sc, def->name) != sc.objects.end())
      return fail(UH_ERROR_INVALID_ARGUMENT,
                  fmt::format("{}: the scene has an object named '{}' already", fn, def->name));
    const std::string what = fmt::format("{}: object '{}'", fn, def->name);
    auto pose = pose_from_arrays(def->position, def->orientation);
    if (!pose) return fail(UH_ERROR_INVALID_ARGUMENT, fmt::format("{}: {}", what, pose.error().message));
    auto shape = shape_from_def(what, def->shape);
    if (!shape) return fail(UH_ERROR_INVALID_ARGUMENT, shape.error().message);
    sc.objects.push_back({.name = def->name, .shape = std::move(shape).value(), .pose = *pose});
    if (def->watch != 0) sc.watch.push_back(def->name);
    if (out_index != nullptr) *out_index = static_cast<int32_t>(sc.objects.size() - 1);
    return UH_OK;
  });
}

uh_status uh_scene_remove_object(uh_scene* scene, const char* name) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    NamedObject found;
    if (auto s = find_named(fn, scene, name, found); s != UH_OK) return s;
    found.box->scene.objects.erase(found.object);
    std::erase(found.box->scene.watch, std::string(name));
    return UH_OK;
  });
}

uh_status uh_scene_set_object_pose(uh_scene* scene, const char* name, const double position[3],
                                   const double orientation[4]) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    NamedObject found;
    if (auto s = find_named(fn, scene, name, found); s != UH_OK) return s;
    auto pose = pose_from_arrays(position, orientation);
    if (!pose) return fail(UH_ERROR_INVALID_ARGUMENT, fmt::format("{}: {}", fn, pose.error().message));
    found.object->pose = *pose;
    return UH_OK;
  });
}

uh_status uh_scene_watch(uh_scene* scene, const char* name, int32_t watch) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    NamedObject found;
    if (auto s = find_named(fn, scene, name, found); s != UH_OK) return s;
    std::erase(found.box->scene.watch, std::string(name));
    if (watch != 0) found.box->scene.watch.push_back(name);
    return UH_OK;
  });
}

uh_status uh_scene_set_tool(uh_scene* scene, const uh_tool_def* def) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    if (auto s = check_struct(fn, "def", def); s != UH_OK) return s;
    const auto box = scene_table().find(handle_value(scene));
    if (!box) return stale(fn, "scene");
    const std::string what = fmt::format("{}: tool", fn);
    if (def->mode != UH_FORCE_6DOF && def->mode != UH_FORCE_3DOF)
      return fail(UH_ERROR_INVALID_ARGUMENT,
                  fmt::format("{}: mode {} is neither UH_FORCE_6DOF nor UH_FORCE_3DOF", what, def->mode));
    if (def->law != UH_FORCE_LAW_GRADIENT && def->law != UH_FORCE_LAW_PAPER)
      return fail(
          UH_ERROR_INVALID_ARGUMENT,
          fmt::format("{}: law {} is neither UH_FORCE_LAW_GRADIENT nor UH_FORCE_LAW_PAPER", what, def->law));
    const auto positive = [](double v) { return v > 0.0 && std::isfinite(v); };
    const auto non_negative = [](double v) { return v >= 0.0 && std::isfinite(v); };
    if (!non_negative(def->stiffness) || !non_negative(def->force_scale) || !non_negative(def->damping) ||
        !non_negative(def->damping_full_volume) || !positive(def->mass_kg) || !positive(def->max_force_n) ||
        !positive(def->max_torque_nm) || !positive(def->workspace_scale))
      return fail(UH_ERROR_INVALID_ARGUMENT,
                  fmt::format("{}: stiffness, force_scale, damping and damping_full_volume must be >= 0; "
                              "mass_kg, max_force_n, "
                              "max_torque_nm and workspace_scale > 0 (all finite)",
                              what));
    if (def->device_driver == nullptr || *def->device_driver == '\0')
      return fail(UH_ERROR_INVALID_ARGUMENT, fmt::format("{}: device_driver is empty", what));
    const Vec3 com{def->center_of_mass[0], def->center_of_mass[1], def->center_of_mass[2]};
    if (!is_finite(com))
      return fail(UH_ERROR_INVALID_ARGUMENT, fmt::format("{}: center_of_mass is not finite", what));
    auto shape = shape_from_def(what, def->shape);
    if (!shape) return fail(UH_ERROR_INVALID_ARGUMENT, shape.error().message);
    auto workspace = pose_from_arrays(def->workspace_offset, def->workspace_rotation);
    if (!workspace)
      return fail(UH_ERROR_INVALID_ARGUMENT,
                  fmt::format("{}: workspace: {}", what, workspace.error().message));
    auto config = controllers::parse_device_config(
        def->device_config_json != nullptr ? def->device_config_json : "{}",
        fmt::format("{} device_config_json", what), std::filesystem::current_path());
    if (!config) return fail(UH_ERROR_INVALID_ARGUMENT, config.error().message);

    controllers::SceneTool tool;
    tool.name = def->name != nullptr ? def->name : "tool";
    tool.shape = std::move(shape).value();
    tool.mode = def->mode == UH_FORCE_3DOF ? forcecomp::ForceMode::k3Dof : forcecomp::ForceMode::k6Dof;
    tool.force = {
        .mass_kg = def->mass_kg,
        .center_of_mass_body = com,
        .law = def->law == UH_FORCE_LAW_PAPER ? forcecomp::ForceLaw::kPaper : forcecomp::ForceLaw::kGradient,
        .stiffness = def->stiffness,
        .force_scale = def->force_scale,
        .damping = def->damping,
        .damping_full_volume = def->damping_full_volume,
        .max_force_n = def->max_force_n,
        .max_torque_nm = def->max_torque_nm};
    tool.device = {.driver = def->device_driver, .config = std::move(config).value()};
    tool.workspace = {
        .world_from_device_base = *workspace, .scale = def->workspace_scale, .handle_from_tool = {}};
    box->scene.tool() = std::move(tool);
    return UH_OK;
  });
}

uh_status uh_scene_set_rates(uh_scene* scene, double haptic_hz, double collision_hz) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    const auto box = scene_table().find(handle_value(scene));
    if (!box) return stale(fn, "scene");
    if (!(haptic_hz >= 1.0 && haptic_hz <= 10000.0) || !(collision_hz >= 0.0 && collision_hz <= 10000.0))
      return fail(
          UH_ERROR_INVALID_ARGUMENT,
          fmt::format("{}: haptic_hz must be in [1, 10000] and collision_hz in [0, 10000] (got {} and {})",
                      fn, haptic_hz, collision_hz));
    box->scene.haptic_hz = haptic_hz;
    box->scene.collision_hz = collision_hz;
    box->scene.force.coupling.period_s = 1.0 / haptic_hz;
    return UH_OK;
  });
}

uh_status uh_scene_object_count(const uh_scene* scene, int32_t* out) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    if (out == nullptr) return null_argument(fn, "out");
    const auto box = scene_table().find(handle_value(scene));
    if (!box) return stale(fn, "scene");
    *out = static_cast<int32_t>(box->scene.objects.size());
    return UH_OK;
  });
}

}  // extern "C"
