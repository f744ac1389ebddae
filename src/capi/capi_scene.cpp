// The C API's scenes: from a file, JSON text or calls (objects, tool, device, watched pairs, rates).

#include <algorithm>
#include <filesystem>
#include <vector>

#include "capi_support.hpp"
#include "uh/collette/ist_builder.hpp"

namespace uh::capi {
namespace {

uh_status add_scene(controllers::Scene scene, uh_scene_id* out) {
  auto box = std::make_shared<SceneBox>();
  box->scene = std::move(scene);
  const std::uint64_t id = scene_table().insert(std::move(box));
  if (id == 0) return table_full("scenes");
  out->bits = id;
  return UH_OK;
}

uh_shape_def default_shape_def() {
  uh_shape_def def{};
  def.struct_size = sizeof def;
  def.spheres = 10000;
  def.meters_per_unit = 1.0;
  return def;
}

uh_object_def default_object_def() {
  uh_object_def def{};
  def.struct_size = sizeof def;
  def.shape = default_shape_def();
  def.orientation[0] = 1.0;
  def.watch = 1;
  return def;
}

uh_tool_def default_tool_def() {
  const forcecomp::ForceParams f{};
  uh_tool_def def{};
  def.struct_size = sizeof def;
  def.name = "tool";
  def.shape = default_shape_def();
  def.mode = UH_FORCE_6DOF;
  def.law = UH_FORCE_LAW_GRADIENT;
  def.stiffness = f.stiffness;
  def.force_scale = f.force_scale;
  def.damping = f.damping;
  def.damping_full_volume = f.damping_full_volume;
  def.mass_kg = f.mass_kg;
  def.center_of_mass[0] = f.center_of_mass_body.x;
  def.center_of_mass[1] = f.center_of_mass_body.y;
  def.center_of_mass[2] = f.center_of_mass_body.z;
  def.max_force_n = f.max_force_n;
  def.max_torque_nm = f.max_torque_nm;
  def.device_driver = "sim-line";
  def.workspace_scale = 1.0;
  def.workspace_rotation[0] = 1.0;
  return def;
}

// The shape of a def: exactly one source; files must exist now; arrays are packed here.
Result<controllers::SceneShape> shape_from_def(const std::string& what, const uh_shape_def& def) {
  if (std::string why = size_problem<uh_shape_def>(fmt::format("{}: shape", what), def.struct_size);
      !why.empty())
    return Error{std::move(why), ErrorKind::kInvalid};
  const int sources = (def.mesh_path != nullptr) + (def.ist_path != nullptr) + (def.tree.bits != 0) +
                      (def.vertices != nullptr || def.indices != nullptr);
  if (sources != 1)
    return Error{
        fmt::format("{}: give exactly one of shape.mesh_path, shape.ist_path, shape.tree or "
                    "shape.vertices with shape.indices (got {})",
                    what, sources)};
  // the numbers and the files are the scene's to check (uh::scene::validate_shape, by the caller)
  controllers::SceneShape shape{.spheres = def.spheres, .meters_per_unit = def.meters_per_unit};
  if (def.mesh_path != nullptr) {
    shape.mesh = std::filesystem::absolute(def.mesh_path);
  } else if (def.ist_path != nullptr) {
    shape.ist = std::filesystem::absolute(def.ist_path);
  } else if (def.tree.bits != 0) {
    const auto box = tree_table().find(def.tree.bits);
    if (!box) return Error{fmt::format("{}: shape.tree is not a valid tree id", what)};
    shape.tree = box->tree;
    // 0 when unknown: the gradient law is then uncalibrated
    if (box->meta.coverage > 0.0 && box->meta.coverage <= 1.0) shape.coverage = box->meta.coverage;
    shape.surface = box->surface_bvh;
    shape.surface_gap_m = box->meta.max_gap;
  } else {
    uh_tree_id tree{0};
    const uh_tree_build_def build{.struct_size = sizeof(uh_tree_build_def),
                                  .spheres = def.spheres,
                                  .meters_per_unit = def.meters_per_unit};
    if (const uh_status built = uh_tree_build_from_arrays(def.vertices, def.vertex_count, def.indices,
                                                          def.triangle_count, &build, &tree);
        built != UH_OK)
      return Error{fmt::format("{}: {}", what, uh_last_error()), error_kind(built)};
    const std::shared_ptr<TreeBox> built = tree_table().remove(tree.bits);
    if (!built) return Error{fmt::format("{}: the tree built from the arrays was lost", what)};
    shape.tree = built->tree;
    if (built->meta.coverage > 0.0 && built->meta.coverage <= 1.0) shape.coverage = built->meta.coverage;
    shape.surface = built->surface_bvh;
    shape.surface_gap_m = built->meta.max_gap;
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

uh_status find_named(const char* fn, uh_scene_id scene, const char* name, NamedObject& out) {
  if (name == nullptr) return null_argument(fn, "name");
  out.box = scene_table().find(scene.bits);
  if (!out.box) return stale(fn, "scene");
  out.object = find_object(out.box->scene, name);
  if (out.object == out.box->scene.objects.end())
    return fail(UH_ERROR_INVALID_ARGUMENT, fmt::format("{}: no object is named '{}'", fn, name));
  return UH_OK;
}

std::vector<controllers::SceneTool>::iterator find_tool(controllers::Scene& scene, const std::string& name) {
  return std::find_if(scene.tools.begin(), scene.tools.end(),
                      [&](const controllers::SceneTool& t) { return t.name == name; });
}

// A tool def (this version's layout, defaults filled in) as the scene's tool, or what is wrong.
Result<controllers::SceneTool> tool_from_def(const std::string& what, const uh_tool_def& def) {
  const auto invalid = [](std::string message) { return Error{std::move(message), ErrorKind::kInvalid}; };
  if (def.mode != UH_FORCE_6DOF && def.mode != UH_FORCE_3DOF)
    return invalid(fmt::format("{}: mode {} is neither UH_FORCE_6DOF nor UH_FORCE_3DOF", what, def.mode));
  if (def.law != UH_FORCE_LAW_GRADIENT && def.law != UH_FORCE_LAW_PAPER)
    return invalid(
        fmt::format("{}: law {} is neither UH_FORCE_LAW_GRADIENT nor UH_FORCE_LAW_PAPER", what, def.law));
  // the numbers' ranges are the scene's to check (uh::scene::validate_tool, by the caller)
  const Vec3 com{def.center_of_mass[0], def.center_of_mass[1], def.center_of_mass[2]};
  const Vec3 tool_offset{def.tool_offset[0], def.tool_offset[1], def.tool_offset[2]};
  auto shape = shape_from_def(what, def.shape);
  if (!shape) return shape.error();
  auto workspace = pose_from_arrays(def.workspace_offset, def.workspace_rotation);
  if (!workspace) return invalid(fmt::format("{}: workspace: {}", what, workspace.error().message));
  auto config = controllers::parse_device_config(
      def.device_config_json != nullptr ? def.device_config_json : "{}",
      fmt::format("{} device_config_json", what), std::filesystem::current_path());
  if (!config) return invalid(config.error().message);

  controllers::SceneTool tool;
  tool.name = def.name != nullptr ? def.name : "tool";
  tool.shape = std::move(shape).value();
  tool.mode = def.mode == UH_FORCE_3DOF ? forcecomp::ForceMode::k3Dof : forcecomp::ForceMode::k6Dof;
  tool.force = {
      .mass_kg = def.mass_kg,
      .center_of_mass_body = com,
      .law = def.law == UH_FORCE_LAW_PAPER ? forcecomp::ForceLaw::kPaper : forcecomp::ForceLaw::kGradient,
      .stiffness = def.stiffness,
      .force_scale = def.force_scale,
      .damping = def.damping,
      .damping_full_volume = def.damping_full_volume,
      .max_force_n = def.max_force_n,
      .max_torque_nm = def.max_torque_nm};
  tool.device = {.driver = def.device_driver != nullptr ? def.device_driver : "",
                 .config = std::move(config).value()};
  tool.workspace = {.world_from_device_base = *workspace,
                    .scale = def.workspace_scale,
                    .handle_from_tool = Pose{Quat{}, tool_offset}};
  return tool;
}

// The tool of uh_scene_set_tool / uh_scene_add_tool: the caller's def read (an older layout with
// this version's defaults for the rest) and converted; its name must not be another tool's.
uh_status read_tool(const char* fn, const uh_tool_def* def, const controllers::Scene& scene,
                    std::size_t replaced, controllers::SceneTool& out) {
  uh_tool_def d = default_tool_def();
  if (auto s = read_def(fn, "def", def, d); s != UH_OK) return s;
  auto tool = tool_from_def(fmt::format("{}: tool", fn), d);
  if (!tool) return fail(tool.error(), UH_ERROR_INVALID_ARGUMENT);
  // its place in the scene once it is in (`tool` while it is the only one)
  const std::size_t count = std::max(scene.tools.size(), replaced + 1);
  const std::string path = count > 1 ? fmt::format("tools[{}]", replaced) : std::string("tool");
  if (Status valid = uh::scene::validate_tool(*tool, path); !valid)
    return fail(UH_ERROR_INVALID_ARGUMENT, fmt::format("{}: {}", fn, valid.error().message));
  for (std::size_t i = 0; i < scene.tools.size(); ++i)
    if (i != replaced && scene.tools[i].name == tool->name)
      return fail(UH_ERROR_INVALID_ARGUMENT,
                  fmt::format("{}: the scene has a tool named '{}' already", fn, tool->name));
  out = std::move(tool).value();
  return UH_OK;
}

}  // namespace
}  // namespace uh::capi

using namespace uh;
using namespace uh::capi;

extern "C" {

uh_status uh_shape_def_init(uh_shape_def* def) { return init_def(__func__, def, default_shape_def); }

uh_status uh_object_def_init(uh_object_def* def) { return init_def(__func__, def, default_object_def); }

uh_status uh_tool_def_init(uh_tool_def* def) { return init_def(__func__, def, default_tool_def); }

int32_t uh_scene_is_valid(uh_scene_id scene) { return is_live(scene_table(), scene.bits); }

uh_status uh_scene_create(const char* name, uh_scene_id* out) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    if (out == nullptr) return null_argument(fn, "out");
    *out = uh_scene_id{0};
    controllers::Scene scene;
    scene.name = name != nullptr ? name : "scene";
    scene.source = fmt::format("scene '{}'", scene.name);
    scene.tools.clear();  // uh_scene_set_tool / uh_scene_add_tool add them
    return add_scene(std::move(scene), out);
  });
}

uh_status uh_scene_load(const char* scene_path, uh_scene_id* out) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    if (out == nullptr) return null_argument(fn, "out");
    *out = uh_scene_id{0};
    auto scene = scene_path != nullptr ? controllers::load_scene(scene_path)
                                       : controllers::default_scene(controllers::default_cache_dir());
    if (!scene) return fail(scene.error(), UH_ERROR_FILE);
    return add_scene(std::move(scene).value(), out);
  });
}

uh_status uh_scene_parse(const char* json_text, const char* base_dir, uh_scene_id* out) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    if (json_text == nullptr) return null_argument(fn, "json_text");
    if (out == nullptr) return null_argument(fn, "out");
    *out = uh_scene_id{0};
    const std::filesystem::path base =
        base_dir != nullptr ? std::filesystem::path(base_dir) : std::filesystem::current_path();
    auto scene = controllers::parse_scene(json_text, "scene JSON", base);
    if (!scene) return fail(scene.error(), UH_ERROR_INVALID_ARGUMENT);
    return add_scene(std::move(scene).value(), out);
  });
}

void uh_scene_destroy(uh_scene_id scene) {
  const char* const fn = __func__;
  const uh_status ignored = guarded(fn, [&]() -> uh_status {
    scene_table().remove(scene.bits);
    return UH_OK;
  });
  (void)ignored;
}

uh_status uh_scene_add_object(uh_scene_id scene, const uh_object_def* def, int32_t* out_index) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    uh_object_def d = default_object_def();
    if (auto s = read_def(fn, "def", def, d); s != UH_OK) return s;
    const auto box = scene_table().find(scene.bits);
    if (!box) return stale(fn, "scene");
    if (d.name == nullptr || *d.name == '\0')
      return fail(UH_ERROR_INVALID_ARGUMENT, fmt::format("{}: def->name is empty", fn));
    controllers::Scene& sc = box->scene;
    if (find_object(sc, d.name) != sc.objects.end())
      return fail(UH_ERROR_INVALID_ARGUMENT,
                  fmt::format("{}: the scene has an object named '{}' already", fn, d.name));
    const std::string what = fmt::format("{}: object '{}'", fn, d.name);
    auto pose = pose_from_arrays(d.position, d.orientation);
    if (!pose) return fail(UH_ERROR_INVALID_ARGUMENT, fmt::format("{}: {}", what, pose.error().message));
    auto shape = shape_from_def(what, d.shape);
    if (!shape) return fail(shape.error(), UH_ERROR_INVALID_ARGUMENT);
    controllers::SceneObject object{.name = d.name, .shape = std::move(shape).value(), .pose = *pose};
    if (Status valid = uh::scene::validate_object(object, fmt::format("objects[{}]", sc.objects.size())); !valid)
      return fail(UH_ERROR_INVALID_ARGUMENT, fmt::format("{}: {}", what, valid.error().message));
    sc.objects.push_back(std::move(object));
    if (d.watch != 0) sc.watch.push_back(d.name);
    if (out_index != nullptr) *out_index = static_cast<int32_t>(sc.objects.size() - 1);
    return UH_OK;
  });
}

uh_status uh_scene_remove_object(uh_scene_id scene, const char* name) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    NamedObject found;
    if (auto s = find_named(fn, scene, name, found); s != UH_OK) return s;
    found.box->scene.objects.erase(found.object);
    std::erase(found.box->scene.watch, std::string(name));
    return UH_OK;
  });
}

uh_status uh_scene_set_object_pose(uh_scene_id scene, const char* name, const double position[3],
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

uh_status uh_scene_watch(uh_scene_id scene, const char* name, int32_t watch) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    NamedObject found;
    if (auto s = find_named(fn, scene, name, found); s != UH_OK) return s;
    std::erase(found.box->scene.watch, std::string(name));
    if (watch != 0) found.box->scene.watch.push_back(name);
    return UH_OK;
  });
}

uh_status uh_scene_set_tool(uh_scene_id scene, const uh_tool_def* def) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    const auto box = scene_table().find(scene.bits);
    if (!box) return stale(fn, "scene");
    controllers::Scene& sc = box->scene;
    controllers::SceneTool tool;
    if (auto s = read_tool(fn, def, sc, 0, tool); s != UH_OK) return s;
    if (sc.tools.empty())
      sc.tools.push_back(std::move(tool));
    else
      sc.tool() = std::move(tool);
    return UH_OK;
  });
}

uh_status uh_scene_add_tool(uh_scene_id scene, const uh_tool_def* def, int32_t* out_index) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    const auto box = scene_table().find(scene.bits);
    if (!box) return stale(fn, "scene");
    controllers::Scene& sc = box->scene;
    controllers::SceneTool tool;
    if (auto s = read_tool(fn, def, sc, sc.tools.size(), tool); s != UH_OK) return s;
    sc.tools.push_back(std::move(tool));
    if (out_index != nullptr) *out_index = static_cast<int32_t>(sc.tools.size() - 1);
    return UH_OK;
  });
}

uh_status uh_scene_remove_tool(uh_scene_id scene, const char* name) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    if (name == nullptr) return null_argument(fn, "name");
    const auto box = scene_table().find(scene.bits);
    if (!box) return stale(fn, "scene");
    const auto tool = find_tool(box->scene, name);
    if (tool == box->scene.tools.end())
      return fail(UH_ERROR_INVALID_ARGUMENT, fmt::format("{}: no tool is named '{}'", fn, name));
    box->scene.tools.erase(tool);
    return UH_OK;
  });
}

uh_status uh_scene_tool_count(uh_scene_id scene, int32_t* out) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    if (out == nullptr) return null_argument(fn, "out");
    const auto box = scene_table().find(scene.bits);
    if (!box) return stale(fn, "scene");
    *out = static_cast<int32_t>(box->scene.tools.size());
    return UH_OK;
  });
}

uh_status uh_scene_set_rates(uh_scene_id scene, double haptic_hz, double collision_hz) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    const auto box = scene_table().find(scene.bits);
    if (!box) return stale(fn, "scene");
    if (Status valid = uh::scene::validate_rates(haptic_hz, collision_hz); !valid)
      return fail(UH_ERROR_INVALID_ARGUMENT, fmt::format("{}: {}", fn, valid.error().message));
    box->scene.haptic_hz = haptic_hz;
    box->scene.collision_hz = collision_hz;
    box->scene.force.coupling.period_s = 1.0 / haptic_hz;
    return UH_OK;
  });
}

uh_status uh_scene_object_count(uh_scene_id scene, int32_t* out) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    if (out == nullptr) return null_argument(fn, "out");
    const auto box = scene_table().find(scene.bits);
    if (!box) return stale(fn, "scene");
    *out = static_cast<int32_t>(box->scene.objects.size());
    return UH_OK;
  });
}

}  // extern "C"
