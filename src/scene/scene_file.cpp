#include "uh/scene/scene.hpp"

#include <cstdlib>
#include <fstream>
#include <initializer_list>
#include <sstream>
#include <string_view>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "embedded_assets.hpp"
#include "uh/core/atomic_file_writer.hpp"
#include "uh/core/json_fields.hpp"
#include "uh/core/regular_file.hpp"
#include "uh/scene/validate.hpp"

namespace uh::scene {
namespace {

using nlohmann::json;

// Reads typed fields out of a JSON object, naming the file and the JSON path in every error.
class FieldReader {
 public:
  explicit FieldReader(std::string source) : source_(std::move(source)) {}

  Error error(const std::string& path, const std::string& what) const {
    return Error{fmt::format("{}: field '{}': {}", source_, path, what)};
  }

  // validate()'s error, which names the field, as this file's (the kind left to the caller, as
  // for every other error of the file)
  Error wrap(const Error& invalid) const { return Error{fmt::format("{}: {}", source_, invalid.message)}; }

  Status require_object(const json& j, const std::string& path) const {
    if (!j.is_object()) return error(path, fmt::format("expected an object, got {}", j.type_name()));
    return Ok{};
  }

  Status check_keys(const json& j, const std::string& path, std::initializer_list<std::string_view> known) const {
    for (const auto& [key, value] : j.items()) {
      bool ok = false;
      for (std::string_view k : known) ok = ok || key == k;
      if (!ok) {
        std::string list;
        for (std::string_view k : known) list += fmt::format("{}{}", list.empty() ? "" : ", ", k);
        return error(join(path, key), fmt::format("unknown field (known here: {})", list));
      }
    }
    return Ok{};
  }

  static std::string join(const std::string& path, std::string_view key) {
    return path.empty() ? std::string(key) : fmt::format("{}.{}", path, key);
  }

  // the type only: ranges are validate()'s (uh/scene/validate.hpp), once the scene is read
  Status number(const json& parent, const std::string& path, std::string_view key, double& out) const {
    const auto it = parent.find(std::string(key));
    if (it == parent.end()) return Ok{};
    if (!it->is_number()) return error(join(path, key), fmt::format("expected a number, got {}", it->type_name()));
    out = it->get<double>();
    return Ok{};
  }

  Status integer(const json& parent, const std::string& path, std::string_view key, std::int64_t& out) const {
    const auto it = parent.find(std::string(key));
    if (it == parent.end()) return Ok{};
    if (!it->is_number_integer()) return error(join(path, key), fmt::format("expected a whole number, got {}", it->dump()));
    out = it->get<std::int64_t>();
    return Ok{};
  }

  Status boolean(const json& parent, const std::string& path, std::string_view key, bool& out) const {
    const auto it = parent.find(std::string(key));
    if (it == parent.end()) return Ok{};
    if (!it->is_boolean()) return error(join(path, key), fmt::format("expected true or false, got {}", it->dump()));
    out = it->get<bool>();
    return Ok{};
  }

  Status string(const json& parent, const std::string& path, std::string_view key, std::string& out, bool required) const {
    const auto it = parent.find(std::string(key));
    if (it == parent.end()) {
      if (required) return error(join(path, key), "missing (expected a string)");
      return Ok{};
    }
    if (!it->is_string() || it->get<std::string>().empty())
      return error(join(path, key), fmt::format("expected a non-empty string, got {}", it->dump()));
    out = it->get<std::string>();
    return Ok{};
  }

  Status vec3(const json& parent, const std::string& path, std::string_view key, Vec3& out) const {
    const auto it = parent.find(std::string(key));
    if (it == parent.end()) return Ok{};
    const std::string p = join(path, key);
    if (!it->is_array() || it->size() != 3) return error(p, fmt::format("expected [x, y, z], got {}", it->dump()));
    double v[3];
    for (std::size_t i = 0; i < 3; ++i) {
      if (!(*it)[i].is_number()) return error(p, fmt::format("expected [x, y, z] of numbers, got {}", it->dump()));
      v[i] = (*it)[i].get<double>();
      if (!std::isfinite(v[i])) return error(p, "expected finite numbers");
    }
    out = {v[0], v[1], v[2]};
    return Ok{};
  }

  Status quat(const json& parent, const std::string& path, std::string_view key, Quat& out) const {
    const auto it = parent.find(std::string(key));
    if (it == parent.end()) return Ok{};
    const std::string p = join(path, key);
    if (!it->is_array() || it->size() != 4)
      return error(p, fmt::format("expected a quaternion [w, x, y, z], got {}", it->dump()));
    double v[4];
    for (std::size_t i = 0; i < 4; ++i) {
      if (!(*it)[i].is_number()) return error(p, fmt::format("expected [w, x, y, z] of numbers, got {}", it->dump()));
      v[i] = (*it)[i].get<double>();
    }
    const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[3] * v[3]);
    if (!(n > 1e-9) || !std::isfinite(n)) return error(p, "expected a non-zero quaternion [w, x, y, z]");
    out = {v[0] / n, v[1] / n, v[2] / n, v[3] / n};
    return Ok{};
  }

  Status pose(const json& parent, const std::string& path, std::string_view key, Pose& out) const {
    const auto it = parent.find(std::string(key));
    if (it == parent.end()) return Ok{};
    const std::string p = join(path, key);
    if (auto s = require_object(*it, p); !s) return s;
    if (auto s = check_keys(*it, p, {"position", "rotation"}); !s) return s;
    if (auto s = vec3(*it, p, "position", out.position); !s) return s;
    return quat(*it, p, "rotation", out.rotation);
  }

 private:
  std::string source_;
};

#define UH_CHECK(expr)          \
  do {                          \
    if (auto s_ = (expr); !s_) return s_.error(); \
  } while (false)

Status read_shape(const FieldReader& r, const json& j, const std::string& path, const std::filesystem::path& base_dir,
                  SceneShape& shape) {
  std::string mesh, ist;
  UH_CHECK(r.string(j, path, "mesh", mesh, false));
  UH_CHECK(r.string(j, path, "ist", ist, false));
  if (mesh.empty() == ist.empty())
    return r.error(path, "give exactly one of 'mesh' (a mesh file, packed on first use) or 'ist' (a .ist file)");
  const auto resolve = [&](const std::string& p) {
    const std::filesystem::path fp(p);
    return fp.is_absolute() ? fp : (base_dir / fp).lexically_normal();
  };
  // the files themselves (present, regular) are validate()'s
  if (!mesh.empty())
    shape.mesh = resolve(mesh);
  else
    shape.ist = resolve(ist);
  UH_CHECK(r.integer(j, path, "spheres", shape.spheres));
  UH_CHECK(r.number(j, path, "meters_per_unit", shape.meters_per_unit));
  return r.number(j, path, "max_sphere_radius", shape.max_sphere_radius);
}

// `objects[i].deformable` (the ranges are validate()'s)
Status read_deformable(const FieldReader& r, const json& j, const std::string& path, SceneDeformable& d) {
  UH_CHECK(r.require_object(j, path));
  UH_CHECK(r.check_keys(j, path,
                        {"young_modulus_pa", "poisson_ratio", "density_kg_m3", "damping", "tetrahedra", "rate_hz", "fixed"}));
  UH_CHECK(r.number(j, path, "young_modulus_pa", d.young_modulus_pa));
  UH_CHECK(r.number(j, path, "poisson_ratio", d.poisson_ratio));
  UH_CHECK(r.number(j, path, "density_kg_m3", d.density_kg_m3));
  UH_CHECK(r.number(j, path, "damping", d.damping));
  UH_CHECK(r.integer(j, path, "tetrahedra", d.tetrahedra));
  UH_CHECK(r.number(j, path, "rate_hz", d.rate_hz));
  const auto fixed = j.find("fixed");
  if (fixed == j.end()) return Ok{};
  const std::string p = FieldReader::join(path, "fixed");
  UH_CHECK(r.require_object(*fixed, p));
  UH_CHECK(r.check_keys(*fixed, p, {"box"}));
  const auto box = fixed->find("box");
  if (box == fixed->end()) return r.error(p, "missing 'box' (expected [[x0, y0, z0], [x1, y1, z1]])");
  const std::string b = FieldReader::join(p, "box");
  if (!box->is_array() || box->size() != 2)
    return r.error(b, fmt::format("expected [[x0, y0, z0], [x1, y1, z1]], got {}", box->dump()));
  SceneDeformable::Box out;
  Vec3* corners[2] = {&out.min, &out.max};
  for (std::size_t i = 0; i < 2; ++i) {
    const json corner{{"corner", (*box)[i]}};
    if (auto s = r.vec3(corner, "", "corner", *corners[i]); !s)
      return r.error(fmt::format("{}[{}]", b, i), fmt::format("expected [x, y, z] of finite numbers, got {}", (*box)[i].dump()));
  }
  d.fixed_box = out;
  return Ok{};
}

// Device settings are text in haptico::DeviceConfig; JSON numbers and [x, y, z] arrays are converted.
Status read_device_config(const FieldReader& r, const json& config, const std::string& path,
                          const std::filesystem::path& base_dir, haptico::DeviceConfig& out) {
  UH_CHECK(r.require_object(config, path));
  for (const auto& [key, value] : config.items()) {
    if (value.is_number()) {
      out.set(key, value.get<double>());
    } else if (value.is_boolean()) {
      out.set(key, value.get<bool>() ? 1.0 : 0.0);
    } else if (value.is_string()) {
      std::string text = value.get<std::string>();
      // a trajectory file is relative to the scene, like meshes
      if (key == "file" && !std::filesystem::path(text).is_absolute()) text = (base_dir / text).lexically_normal().string();
      out.set(key, text);
    } else if (value.is_array() && value.size() == 3 && value[0].is_number() && value[1].is_number() &&
               value[2].is_number()) {
      out.set(key, Vec3{value[0].get<double>(), value[1].get<double>(), value[2].get<double>()});
    } else {
      return r.error(FieldReader::join(path, key),
                     fmt::format("expected a number, a string, a boolean or [x, y, z], got {}", value.dump()));
    }
  }
  return Ok{};
}

Status read_device(const FieldReader& r, const json& j, const std::string& path, const std::filesystem::path& base_dir,
                   SceneDevice& device) {
  UH_CHECK(r.require_object(j, path));
  UH_CHECK(r.check_keys(j, path, {"driver", "config"}));
  UH_CHECK(r.string(j, path, "driver", device.driver, true));
  const auto it = j.find("config");
  if (it == j.end()) return Ok{};
  return read_device_config(r, *it, FieldReader::join(path, "config"), base_dir, device.config);
}

Status read_force_params(const FieldReader& r, const json& j, const std::string& path, SceneTool& tool) {
  UH_CHECK(r.require_object(j, path));
  UH_CHECK(r.check_keys(j, path,
                        {"mode", "law", "stiffness", "force_scale", "damping", "damping_full_volume",
                         "mass_kg", "center_of_mass", "max_force_n", "max_torque_nm"}));
  std::string mode = "6dof";
  UH_CHECK(r.string(j, path, "mode", mode, false));
  if (mode == "6dof") {
    tool.mode = forcecomp::ForceMode::k6Dof;
  } else if (mode == "3dof") {
    tool.mode = forcecomp::ForceMode::k3Dof;
  } else {
    return r.error(FieldReader::join(path, "mode"), fmt::format("expected \"3dof\" or \"6dof\", got \"{}\"", mode));
  }
  auto& f = tool.force;
  std::string law = "gradient";
  UH_CHECK(r.string(j, path, "law", law, false));
  if (law == "gradient") {
    f.law = forcecomp::ForceLaw::kGradient;
  } else if (law == "paper") {
    f.law = forcecomp::ForceLaw::kPaper;
  } else {
    return r.error(FieldReader::join(path, "law"),
                   fmt::format("expected \"gradient\" or \"paper\", got \"{}\"", law));
  }
  // each law has its own stiffness in its own unit: a value meant for the other law would feel
  // wrong by orders of magnitude, so it is refused rather than ignored
  if (f.law == forcecomp::ForceLaw::kGradient && j.contains("force_scale"))
    return r.error(
        FieldReader::join(path, "force_scale"),
        "is the paper law's stiffness [N/m^3]; the gradient law (the default) takes 'stiffness' [N/m^2] "
        "(or set \"law\": \"paper\")");
  if (f.law == forcecomp::ForceLaw::kPaper && j.contains("stiffness"))
    return r.error(FieldReader::join(path, "stiffness"),
                   "is the gradient law's stiffness [N/m^2]; the paper law takes 'force_scale' [N/m^3]");
  UH_CHECK(r.number(j, path, "stiffness", f.stiffness));
  UH_CHECK(r.number(j, path, "force_scale", f.force_scale));
  UH_CHECK(r.number(j, path, "damping", f.damping));
  UH_CHECK(r.number(j, path, "damping_full_volume", f.damping_full_volume));
  UH_CHECK(r.number(j, path, "mass_kg", f.mass_kg));
  UH_CHECK(r.vec3(j, path, "center_of_mass", f.center_of_mass_body));
  UH_CHECK(r.number(j, path, "max_force_n", f.max_force_n));
  UH_CHECK(r.number(j, path, "max_torque_nm", f.max_torque_nm));
  return Ok{};
}

Status read_workspace(const FieldReader& r, const json& j, const std::string& path, WorkspaceMapping& w) {
  UH_CHECK(r.require_object(j, path));
  UH_CHECK(r.check_keys(j, path, {"scale", "offset", "rotation", "tool_offset"}));
  UH_CHECK(r.number(j, path, "scale", w.scale));
  UH_CHECK(r.vec3(j, path, "offset", w.world_from_device_base.position));
  UH_CHECK(r.quat(j, path, "rotation", w.world_from_device_base.rotation));
  UH_CHECK(r.vec3(j, path, "tool_offset", w.handle_from_tool.position));
  return Ok{};
}

Status read_force_options(const FieldReader& r, const json& j, const std::string& path, Scene& scene) {
  ForceControllerOptions& o = scene.force;
  UH_CHECK(r.require_object(j, path));
  UH_CHECK(r.check_keys(j, path, {"multi_rate", "tick_force", "safety", "coupling", "proxy"}));
  UH_CHECK(r.boolean(j, path, "multi_rate", o.multi_rate));
  std::string tick_force = "model";
  UH_CHECK(r.string(j, path, "tick_force", tick_force, false));
  if (tick_force == "model") {
    o.tick_force = TickForce::kModel;
  } else if (tick_force == "exact") {
    o.tick_force = TickForce::kExact;
  } else {
    return r.error(FieldReader::join(path, "tick_force"),
                   fmt::format("expected \"model\" or \"exact\", got \"{}\"", tick_force));
  }
  if (const auto it = j.find("safety"); it != j.end()) {
    const std::string p = FieldReader::join(path, "safety");
    UH_CHECK(r.require_object(*it, p));
    UH_CHECK(r.check_keys(*it, p,
                          {"max_force_n", "max_torque_nm", "max_force_rate_n_per_s",
                           "max_torque_rate_nm_per_s", "watchdog_max_age_s", "watchdog_ramp_s"}));
    UH_CHECK(r.number(*it, p, "max_force_n", scene.safety_limits.max_force_n));
    UH_CHECK(r.number(*it, p, "max_torque_nm", scene.safety_limits.max_torque_nm));
    UH_CHECK(r.number(*it, p, "max_force_rate_n_per_s", scene.rate_limit.max_force_n_per_s));
    UH_CHECK(r.number(*it, p, "max_torque_rate_nm_per_s", scene.rate_limit.max_torque_nm_per_s));
    UH_CHECK(r.number(*it, p, "watchdog_max_age_s", o.safety.watchdog.max_age_s));
    UH_CHECK(r.number(*it, p, "watchdog_ramp_s", o.safety.watchdog.ramp_s));
  }
  if (const auto it = j.find("coupling"); it != j.end()) {
    const std::string p = FieldReader::join(path, "coupling");
    UH_CHECK(r.require_object(*it, p));
    UH_CHECK(r.check_keys(*it, p, {"enabled", "stiffness", "damping", "device_damping", "angular_stiffness",
                                   "angular_damping", "device_angular_damping", "passivity_margin", "proxy_mass_kg",
                                   "proxy_inertia_kg_m2"}));
    auto& c = o.coupling;
    UH_CHECK(r.boolean(*it, p, "enabled", o.use_coupling));
    UH_CHECK(r.number(*it, p, "stiffness", c.stiffness));
    UH_CHECK(r.number(*it, p, "damping", c.damping));
    UH_CHECK(r.number(*it, p, "device_damping", c.device_damping));
    // absent: derived from the linear spring and the tool's extent (VirtualCouplingOptions)
    if (it->contains("angular_stiffness")) {
      double angular = 0.0;
      UH_CHECK(r.number(*it, p, "angular_stiffness", angular));
      c.angular_stiffness = angular;
    }
    UH_CHECK(r.number(*it, p, "angular_damping", c.angular_damping));
    UH_CHECK(r.number(*it, p, "device_angular_damping", c.device_angular_damping));
    UH_CHECK(r.number(*it, p, "passivity_margin", c.passivity_margin));
    UH_CHECK(r.number(*it, p, "proxy_mass_kg", c.proxy_mass_kg));
    UH_CHECK(r.number(*it, p, "proxy_inertia_kg_m2", c.proxy_inertia_kg_m2));
  }
  if (const auto it = j.find("proxy"); it != j.end()) {
    const std::string p = FieldReader::join(path, "proxy");
    UH_CHECK(r.require_object(*it, p));
    UH_CHECK(r.check_keys(*it, p, {"enabled", "step_m", "penetration_m", "max_constraints", "smoothing_m"}));
    auto& x = o.proxy;
    UH_CHECK(r.boolean(*it, p, "enabled", x.enabled));
    UH_CHECK(r.number(*it, p, "step_m", x.step_m));
    UH_CHECK(r.number(*it, p, "penetration_m", x.penetration_m));
    UH_CHECK(r.number(*it, p, "smoothing_m", x.smoothing_m));
    double capacity = x.max_constraints;
    UH_CHECK(r.number(*it, p, "max_constraints", capacity));
    // saturated into the field's type (a cast of a value beyond it is undefined); validate() then
    // refuses what is outside the range
    x.max_constraints = static_cast<std::int32_t>(std::clamp(capacity, -2.0e9, 2.0e9));
    // a file that asks for both names the clash (force.coupling alone turns the proxy off)
    if (x.enabled && o.use_coupling && it->contains("enabled"))
      return r.error(p, "the proxy and force.coupling (the simulated tool of the penalty path) exclude each other");
  }
  if (o.use_coupling) o.proxy.enabled = false;  // the proxy is the default, the coupling a choice
  return Ok{};
}

// A material: an inline object or the name of an entry of the scene's top-level `materials` table
// (read first, each entry checked under its own path `materials.NAME`).
Status read_material_fields(const FieldReader& r, const json& j, const std::string& path,
                            forcecomp::Material& m) {
  UH_CHECK(r.require_object(j, path));
  UH_CHECK(r.check_keys(j, path, {"stiffness", "damping", "friction", "texture"}));
  if (j.contains("stiffness")) {
    UH_CHECK(r.number(j, path, "stiffness", m.stiffness));
    m.has_stiffness = true;
  }
  if (j.contains("damping")) {
    UH_CHECK(r.number(j, path, "damping", m.damping));
    m.has_damping = true;
  }
  if (const auto it = j.find("friction"); it != j.end()) {
    const std::string p = FieldReader::join(path, "friction");
    UH_CHECK(r.require_object(*it, p));
    UH_CHECK(r.check_keys(*it, p, {"static", "dynamic"}));
    if (!it->contains("static") || !it->contains("dynamic"))
      return r.error(p,
                     "expected both 'static' (the coefficient at breakaway) and 'dynamic' (while sliding)");
    UH_CHECK(r.number(*it, p, "static", m.friction_static));
    UH_CHECK(r.number(*it, p, "dynamic", m.friction_dynamic));
    m.has_friction = true;
  }
  if (const auto it = j.find("texture"); it != j.end()) {
    const std::string p = FieldReader::join(path, "texture");
    UH_CHECK(r.require_object(*it, p));
    std::string type;
    UH_CHECK(r.string(*it, p, "type", type, true));
    if (type == "grating") {
      UH_CHECK(r.check_keys(*it, p, {"type", "period", "amplitude", "direction"}));
      if (!it->contains("period") || !it->contains("amplitude"))
        return r.error(p, "a grating needs 'period' [m] and 'amplitude' [m]");
      double period = 0.0, amplitude = 0.0;
      Vec3 direction{1.0, 0.0, 0.0};
      UH_CHECK(r.number(*it, p, "period", period));
      UH_CHECK(r.number(*it, p, "amplitude", amplitude));
      UH_CHECK(r.vec3(*it, p, "direction", direction));
      m.texture = forcecomp::make_grating(period, amplitude, direction);
    } else if (type == "random") {
      UH_CHECK(r.check_keys(*it, p, {"type", "roughness", "correlation_length", "seed"}));
      if (!it->contains("roughness") || !it->contains("correlation_length"))
        return r.error(p, "a random texture needs 'roughness' [m] and 'correlation_length' [m]");
      double roughness = 0.0, length = 0.0;
      std::int64_t seed = 1;
      UH_CHECK(r.number(*it, p, "roughness", roughness));
      UH_CHECK(r.number(*it, p, "correlation_length", length));
      UH_CHECK(r.integer(*it, p, "seed", seed));
      // the seed is no field of the scene (the waves are drawn from it here): its range is the file's
      if (seed < 0 || seed > (std::int64_t{1} << 53))
        return r.error(FieldReader::join(p, "seed"),
                       fmt::format("expected a whole number in [0, {}], got {}", std::int64_t{1} << 53, seed));
      m.texture = forcecomp::make_random_texture(roughness, length, static_cast<std::uint64_t>(seed));
    } else {
      return r.error(FieldReader::join(p, "type"),
                     fmt::format("expected \"grating\" or \"random\", got \"{}\"", type));
    }
  }
  return Ok{};
}

using MaterialTable = std::vector<std::pair<std::string, forcecomp::Material>>;

Status read_material_table(const FieldReader& r, const json& root, MaterialTable& table) {
  const auto it = root.find("materials");
  if (it == root.end()) return Ok{};
  if (!it->is_object())
    return r.error("materials",
                   fmt::format("expected an object of named materials, got {}", it->type_name()));
  for (const auto& [name, value] : it->items()) {
    forcecomp::Material m;
    const std::string path = FieldReader::join("materials", name);
    UH_CHECK(read_material_fields(r, value, path, m));
    if (Status valid = validate_material(m, path); !valid) return r.wrap(valid.error());
    table.emplace_back(name, m);
  }
  return Ok{};
}

// `material` of an object or the tool: a name from the table or an inline object
Status read_material(const FieldReader& r, const json& parent, const std::string& path,
                     const MaterialTable& table, forcecomp::Material& out) {
  const auto it = parent.find("material");
  if (it == parent.end()) return Ok{};
  const std::string p = FieldReader::join(path, "material");
  if (it->is_string()) {
    for (const auto& [name, m] : table) {
      if (name != it->get<std::string>()) continue;
      out = m;
      return Ok{};
    }
    std::string known;
    for (const auto& entry : table) known += fmt::format("{}'{}'", known.empty() ? "" : ", ", entry.first);
    return r.error(p, fmt::format("no material is named '{}' (the scene's 'materials' has {})",
                                  it->get<std::string>(), known.empty() ? "none" : known));
  }
  return read_material_fields(r, *it, p, out);
}

// one tool object (`tool`, or `tools[i]` at `path`)
Status read_tool(const FieldReader& r, const json& j, const std::string& path,
                 const std::filesystem::path& base_dir, const MaterialTable& materials, SceneTool& tool) {
  UH_CHECK(r.require_object(j, path));
  UH_CHECK(r.check_keys(j, path,
                        {"name", "mesh", "ist", "spheres", "max_sphere_radius", "meters_per_unit", "force",
                         "device", "workspace", "material"}));
  UH_CHECK(r.string(j, path, "name", tool.name, false));
  UH_CHECK(read_shape(r, j, path, base_dir, tool.shape));
  if (const auto it = j.find("force"); it != j.end())
    UH_CHECK(read_force_params(r, *it, FieldReader::join(path, "force"), tool));
  UH_CHECK(read_material(r, j, path, materials, tool.material));
  const auto device = j.find("device");
  if (device == j.end())
    return r.error(FieldReader::join(path, "device"),
                   "missing (expected {\"driver\": ..., \"config\": {...}})");
  UH_CHECK(read_device(r, *device, FieldReader::join(path, "device"), base_dir, tool.device));
  if (const auto it = j.find("workspace"); it != j.end())
    UH_CHECK(read_workspace(r, *it, FieldReader::join(path, "workspace"), tool.workspace));
  return Ok{};
}

// `tool` (one tool) or `tools` (a non-empty list), never both
Status read_tools(const FieldReader& r, const json& root, const std::filesystem::path& base_dir,
                  const MaterialTable& materials, Scene& scene) {
  const auto one = root.find("tool");
  const auto many = root.find("tools");
  if (one != root.end() && many != root.end())
    return r.error("tools", "a scene has either 'tool' (one tool) or 'tools' (a list of tools), not both");
  if (one == root.end() && many == root.end())
    return r.error("tool", "missing (expected the tool object, or 'tools': a list of tool objects)");
  scene.tools.clear();
  if (one != root.end()) {
    UH_CHECK(read_tool(r, *one, "tool", base_dir, materials, scene.tools.emplace_back()));
  } else {
    if (!many->is_array() || many->empty())
      return r.error("tools", fmt::format("expected a non-empty list of tool objects, got {}",
                                          many->is_array() ? "an empty list" : many->type_name()));
    for (std::size_t i = 0; i < many->size(); ++i) {
      const std::string path = fmt::format("tools[{}]", i);
      SceneTool tool;
      tool.name = fmt::format("tool{}", i + 1);
      UH_CHECK(read_tool(r, (*many)[i], path, base_dir, materials, tool));
      scene.tools.push_back(std::move(tool));
    }
  }
  return Ok{};
}

Result<json> parse_json(std::string_view json_text, const std::string& source) {
  auto document = parse_json_document(json_text);
  if (!document) return Error{fmt::format("{}: {}", source, document.error().message)};
  return document;
}

}  // namespace

Result<Scene> parse_scene(std::string_view json_text, const std::string& source, const std::filesystem::path& base_dir) {
  auto parsed = parse_json(json_text, source);
  if (!parsed) return parsed.error();
  const json& root = *parsed;
  const FieldReader r(source);
  if (!root.is_object()) return Error{fmt::format("{}: expected a JSON object at the top level", source)};
  UH_CHECK(r.check_keys(root, "",
                        {"name", "description", "rates", "seconds", "objects", "tool", "tools", "watch",
                         "force", "collision", "materials"}));
  MaterialTable materials;
  UH_CHECK(read_material_table(r, root, materials));

  Scene scene;
  scene.source = source;
  scene.name = std::filesystem::path(source).stem().string();
  UH_CHECK(r.string(root, "", "name", scene.name, false));
  UH_CHECK(r.number(root, "", "seconds", scene.seconds));
  if (const auto it = root.find("rates"); it != root.end()) {
    UH_CHECK(r.require_object(*it, "rates"));
    UH_CHECK(r.check_keys(*it, "rates", {"haptic_hz", "collision_hz"}));
    UH_CHECK(r.number(*it, "rates", "haptic_hz", scene.haptic_hz));
    UH_CHECK(r.number(*it, "rates", "collision_hz", scene.collision_hz));
  }

  if (const auto it = root.find("collision"); it != root.end()) {
    UH_CHECK(r.require_object(*it, "collision"));
    UH_CHECK(r.check_keys(*it, "collision", {"contact_margin", "coherence_skin"}));
    UH_CHECK(r.number(*it, "collision", "contact_margin", scene.contact_margin));
    UH_CHECK(r.number(*it, "collision", "coherence_skin", scene.coherence_skin));
  }

  const auto objects = root.find("objects");
  if (objects == root.end()) return r.error("objects", "missing (expected a list of objects)");
  if (!objects->is_array()) return r.error("objects", "expected a non-empty list of objects");
  for (std::size_t i = 0; i < objects->size(); ++i) {
    const json& o = (*objects)[i];
    const std::string path = fmt::format("objects[{}]", i);
    UH_CHECK(r.require_object(o, path));
    UH_CHECK(r.check_keys(
        o, path,
        {"name", "mesh", "ist", "spheres", "max_sphere_radius", "meters_per_unit", "pose", "material",
         "deformable"}));
    SceneObject object;
    UH_CHECK(r.string(o, path, "name", object.name, true));
    UH_CHECK(read_shape(r, o, path, base_dir, object.shape));
    UH_CHECK(r.pose(o, path, "pose", object.pose));
    UH_CHECK(read_material(r, o, path, materials, object.material));
    if (const auto it = o.find("deformable"); it != o.end())
      UH_CHECK(read_deformable(r, *it, FieldReader::join(path, "deformable"), object.deformable.emplace()));
    scene.objects.push_back(std::move(object));
  }

  UH_CHECK(read_tools(r, root, base_dir, materials, scene));

  if (const auto it = root.find("watch"); it != root.end()) {
    if (!it->is_array()) return r.error("watch", "expected a list of object names");
    for (std::size_t i = 0; i < it->size(); ++i) {
      const json& name = (*it)[i];
      const std::string path = fmt::format("watch[{}]", i);
      if (!name.is_string()) return r.error(path, "expected an object name");
      scene.watch.push_back(name.get<std::string>());
    }
  } else {
    for (const auto& o : scene.objects) scene.watch.push_back(o.name);
  }

  if (const auto it = root.find("force"); it != root.end()) UH_CHECK(read_force_options(r, *it, "force", scene));
  if (Status valid = validate(scene); !valid) return r.wrap(valid.error());
  scene.force.coupling.period_s = 1.0 / scene.haptic_hz;
  return scene;
}

Result<haptico::DeviceConfig> parse_device_config(std::string_view json_text, const std::string& source,
                                                  const std::filesystem::path& base_dir) {
  auto root = parse_json(json_text, source);
  if (!root) return root.error();
  const FieldReader r(source);
  haptico::DeviceConfig config;
  UH_CHECK(read_device_config(r, *root, "", base_dir, config));
  return config;
}

Result<std::string> read_scene_file(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    return Error{fmt::format("{}: cannot open the scene file", path.string())};
  return read_regular_file(path, kMaxSceneFileBytes);
}

Result<Scene> load_scene(const std::filesystem::path& path) {
  auto text = read_scene_file(path);
  if (!text) return text.error();
  return parse_scene(*text, path.string(), path.parent_path());
}

namespace {

// Writes `text` to `path` unless the file already holds exactly that text (atomic replace).
Status write_if_changed(const std::filesystem::path& path, std::string_view text) {
  {
    std::ifstream in(path, std::ios::binary);
    if (in) {
      std::stringstream existing;
      existing << in.rdbuf();
      if (existing.str() == text) return Ok{};
    }
  }
  return write_file_atomically(path, text);
}

}  // namespace

Result<std::filesystem::path> write_default_scene(const std::filesystem::path& cache_dir) {
  std::error_code ec;
  const std::filesystem::path dir = cache_dir / "default-scene";
  std::filesystem::create_directories(dir / "scenes", ec);
  std::filesystem::create_directories(dir / "assets" / "meshes", ec);
  if (ec) return Error{fmt::format("{}: cannot create the cache folder: {}", dir.string(), ec.message())};
  std::filesystem::path scene_file;
  for (const auto& file : embedded::files()) {
    if (auto s = write_if_changed(dir / file.path, file.text); !s) return s.error();
    if (file.text.data() == embedded::default_scene_json().data()) scene_file = dir / file.path;
  }
  return scene_file;
}

Result<Scene> default_scene(const std::filesystem::path& cache_dir) {
  auto file = write_default_scene(cache_dir);
  if (!file) return file.error();
  return parse_scene(embedded::default_scene_json(), "<embedded default scene>", file->parent_path());
}

}  // namespace uh::scene
