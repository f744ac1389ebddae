// The scene writer: a Scene as the JSON file load_scene() reads back to the same scene. Every
// field is written, defaults too, so that a written file says all it means; materials are written
// inline (the file's named table is a convenience of hand-written files).

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "uh/scene/scene.hpp"
#include "uh/scene/validate.hpp"

namespace uh::scene {
namespace {

using nlohmann::json;

json array_of(const Vec3& v) { return json::array({v.x, v.y, v.z}); }
json array_of(const Quat& q) { return json::array({q.w, q.x, q.y, q.z}); }

// a shape's file fields; a tree held only in memory has no file to name
Result<json> shape_json(const SceneShape& shape, const std::string& path) {
  json j;
  if (!shape.mesh.empty())
    j["mesh"] = shape.mesh.generic_string();
  else if (!shape.ist.empty())
    j["ist"] = shape.ist.generic_string();
  else
    return Error{fmt::format("{}: its tree is held in memory, with no mesh or .ist file a scene file can name", path),
                 ErrorKind::kInvalid};
  j["spheres"] = shape.spheres;
  j["meters_per_unit"] = shape.meters_per_unit;
  j["max_sphere_radius"] = shape.max_sphere_radius;
  return j;
}

json texture_json(const forcecomp::Texture& t) {
  if (t.kind == forcecomp::TextureKind::kGrating)
    return {{"type", "grating"}, {"period", t.period_m}, {"amplitude", t.amplitude_m}, {"direction", array_of(t.direction)}};
  return {{"type", "random"},
          {"roughness", t.roughness_m},
          {"correlation_length", t.correlation_length_m},
          {"seed", t.seed}};
}

// only what the material sets: an unset property falls back to the tool's force parameters
json material_json(const forcecomp::Material& m) {
  json j = json::object();
  if (m.has_stiffness) j["stiffness"] = m.stiffness;
  if (m.has_damping) j["damping"] = m.damping;
  if (m.has_friction) j["friction"] = {{"static", m.friction_static}, {"dynamic", m.friction_dynamic}};
  if (m.texture.kind != forcecomp::TextureKind::kNone) j["texture"] = texture_json(m.texture);
  return j;
}

json deformable_json(const SceneDeformable& d) {
  json j{{"young_modulus_pa", d.young_modulus_pa},
         {"poisson_ratio", d.poisson_ratio},
         {"density_kg_m3", d.density_kg_m3},
         {"damping", d.damping},
         {"rate_hz", d.rate_hz}};
  if (d.tetrahedra != 0) j["tetrahedra"] = d.tetrahedra;  // left out: chosen from the object's size
  if (d.fixed_box) j["fixed"] = {{"box", json::array({array_of(d.fixed_box->min), array_of(d.fixed_box->max)})}};
  return j;
}

// device settings are text: what the config reads as [x, y, z] or a number goes back as one
json config_value(const haptico::DeviceConfig& config, const std::string& key, const std::string& text) {
  if (const auto v = config.vec3(key, {}); v) return array_of(*v);
  if (const auto n = config.number(key, 0.0); n) return *n;
  return text;
}

json force_params_json(const SceneTool& tool) {
  const forcecomp::ForceParams& f = tool.force;
  const bool gradient = f.law == forcecomp::ForceLaw::kGradient;
  json j{{"mode", tool.mode == forcecomp::ForceMode::k3Dof ? "3dof" : "6dof"},
         {"law", gradient ? "gradient" : "paper"},
         {"damping", f.damping},
         {"damping_full_volume", f.damping_full_volume},
         {"mass_kg", f.mass_kg},
         {"center_of_mass", array_of(f.center_of_mass_body)},
         {"max_force_n", f.max_force_n},
         {"max_torque_nm", f.max_torque_nm}};
  // each law reads its own stiffness key and refuses the other's
  j[gradient ? "stiffness" : "force_scale"] = gradient ? f.stiffness : f.force_scale;
  return j;
}

Result<json> tool_json(const SceneTool& tool, const std::string& path) {
  auto j = shape_json(tool.shape, path);
  if (!j) return j;
  json& t = *j;
  t["name"] = tool.name;
  t["force"] = force_params_json(tool);
  if (const json m = material_json(tool.material); !m.empty()) t["material"] = m;
  json config = json::object();
  for (const auto& [key, value] : tool.device.config.values())
    config[key] = config_value(tool.device.config, key, value);
  t["device"] = {{"driver", tool.device.driver}, {"config", config}};
  t["workspace"] = {{"scale", tool.workspace.scale},
                    {"offset", array_of(tool.workspace.world_from_device_base.position)},
                    {"rotation", array_of(tool.workspace.world_from_device_base.rotation)},
                    {"tool_offset", array_of(tool.workspace.handle_from_tool.position)}};
  return j;
}

json force_options_json(const Scene& scene) {
  const ForceControllerOptions& o = scene.force;
  const auto& c = o.coupling;
  const auto& x = o.proxy;
  json j = {{"multi_rate", o.multi_rate},
          {"tick_force", o.tick_force == TickForce::kExact ? "exact" : "model"},
          {"safety",
           {{"max_force_n", scene.safety_limits.max_force_n},
            {"max_torque_nm", scene.safety_limits.max_torque_nm},
            {"max_force_rate_n_per_s", scene.rate_limit.max_force_n_per_s},
            {"max_torque_rate_nm_per_s", scene.rate_limit.max_torque_nm_per_s},
            {"watchdog_max_age_s", o.safety.watchdog.max_age_s},
            {"watchdog_ramp_s", o.safety.watchdog.ramp_s}}},
          {"coupling",
           {{"enabled", o.use_coupling},
            {"stiffness", c.stiffness},
            {"damping", c.damping},
            {"device_damping", c.device_damping},
            {"angular_damping", c.angular_damping},
            {"device_angular_damping", c.device_angular_damping},
            {"passivity_margin", c.passivity_margin},
            {"proxy_mass_kg", c.proxy_mass_kg},
            {"proxy_inertia_kg_m2", c.proxy_inertia_kg_m2}}},
          {"proxy",
           {{"enabled", x.enabled},
            {"step_m", x.step_m},
            {"penetration_m", x.penetration_m},
            {"max_constraints", x.max_constraints},
            {"smoothing_m", x.smoothing_m}}}};
  // unset: derived from the linear spring and the tool's extent, as when read back
  if (c.angular_stiffness) j["coupling"]["angular_stiffness"] = *c.angular_stiffness;
  return j;
}

}  // namespace

Result<std::string> write_scene(const Scene& scene) {
  if (Status valid = validate(scene); !valid) return valid.error();
  json root{{"name", scene.name},
            {"seconds", scene.seconds},
            {"rates", {{"haptic_hz", scene.haptic_hz}, {"collision_hz", scene.collision_hz}}},
            {"collision", {{"contact_margin", scene.contact_margin}, {"coherence_skin", scene.coherence_skin}}},
            {"watch", scene.watch},
            {"force", force_options_json(scene)}};
  json objects = json::array();
  for (std::size_t i = 0; i < scene.objects.size(); ++i) {
    const SceneObject& object = scene.objects[i];
    auto j = shape_json(object.shape, fmt::format("{}: objects[{}] '{}'", scene.source, i, object.name));
    if (!j) return j.error();
    (*j)["name"] = object.name;
    (*j)["pose"] = {{"position", array_of(object.pose.position)}, {"rotation", array_of(object.pose.rotation)}};
    if (const json m = material_json(object.material); !m.empty()) (*j)["material"] = m;
    if (object.deformable) (*j)["deformable"] = deformable_json(*object.deformable);
    objects.push_back(std::move(*j));
  }
  root["objects"] = std::move(objects);
  json tools = json::array();
  for (std::size_t i = 0; i < scene.tools.size(); ++i) {
    auto j = tool_json(scene.tools[i], fmt::format("{}: tools[{}] '{}'", scene.source, i, scene.tools[i].name));
    if (!j) return j.error();
    tools.push_back(std::move(*j));
  }
  root["tools"] = std::move(tools);
  return root.dump(2) + "\n";
}

}  // namespace uh::scene
