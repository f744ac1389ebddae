#include "uh/controllers/scene.hpp"

#include <cstdlib>
#include <fstream>
#include <initializer_list>
#include <sstream>
#include <string_view>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "embedded_assets.hpp"
#include "uh/collette/ist_builder.hpp"
#include "uh/collette/ist_file.hpp"
#include "uh/collette/mesh_import.hpp"
#include "uh/collette/sphere_tree_builder.hpp"
#include "uh/core/atomic_file_writer.hpp"
#include "uh/core/json_fields.hpp"
#include "uh/core/regular_file.hpp"

namespace uh::controllers {
namespace {

using nlohmann::json;

// Reads typed fields out of a JSON object, naming the file and the JSON path in every error.
class FieldReader {
 public:
  explicit FieldReader(std::string source) : source_(std::move(source)) {}

  Error error(const std::string& path, const std::string& what) const {
    return Error{fmt::format("{}: field '{}': {}", source_, path, what)};
  }

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

  Status number(const json& parent, const std::string& path, std::string_view key, double& out, double min,
                double max) const {
    const auto it = parent.find(std::string(key));
    if (it == parent.end()) return Ok{};
    const std::string p = join(path, key);
    if (!it->is_number()) return error(p, fmt::format("expected a number, got {}", it->type_name()));
    const double v = it->get<double>();
    if (!std::isfinite(v) || v < min || v > max) return error(p, fmt::format("expected a number in [{}, {}], got {}", min, max, v));
    out = v;
    return Ok{};
  }

  Status integer(const json& parent, const std::string& path, std::string_view key, std::int64_t& out,
                 std::int64_t min, std::int64_t max) const {
    const auto it = parent.find(std::string(key));
    if (it == parent.end()) return Ok{};
    const std::string p = join(path, key);
    if (!it->is_number_integer()) return error(p, fmt::format("expected a whole number, got {}", it->dump()));
    const auto v = it->get<std::int64_t>();
    if (v < min || v > max) return error(p, fmt::format("expected a whole number in [{}, {}], got {}", min, max, v));
    out = v;
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
  // a directory, FIFO or device is refused here, when the scene is read, not when it is packed
  const auto check_file = [&](const std::filesystem::path& file, const char* key) -> Status {
    std::error_code ec;
    if (!std::filesystem::exists(file, ec))
      return r.error(FieldReader::join(path, key), fmt::format("file not found: {}", file.string()));
    if (auto checked = check_regular_file(file, kMaxMeshFileBytes); !checked)
      return r.error(FieldReader::join(path, key), checked.error().message);
    return Ok{};
  };
  if (!mesh.empty()) {
    shape.mesh = resolve(mesh);
    UH_CHECK(check_file(shape.mesh, "mesh"));
  } else {
    shape.ist = resolve(ist);
    UH_CHECK(check_file(shape.ist, "ist"));
  }
  UH_CHECK(r.integer(j, path, "spheres", shape.spheres, 1, 2'000'000));
  UH_CHECK(r.number(j, path, "meters_per_unit", shape.meters_per_unit, 1e-9, 1e6));
  if (j.contains("max_sphere_radius")) {
    if (!ist.empty())
      return r.error(FieldReader::join(path, "max_sphere_radius"),
                     "applies only when packing a 'mesh' (a .ist file is packed already)");
    UH_CHECK(r.number(j, path, "max_sphere_radius", shape.max_sphere_radius, 1e-9, 1e6));
  }
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
  UH_CHECK(r.number(j, path, "stiffness", f.stiffness, 0.0, 1e12));
  UH_CHECK(r.number(j, path, "force_scale", f.force_scale, 0.0, 1e15));
  UH_CHECK(r.number(j, path, "damping", f.damping, 0.0, 1e6));
  UH_CHECK(r.number(j, path, "damping_full_volume", f.damping_full_volume, 0.0, 1.0));
  UH_CHECK(r.number(j, path, "mass_kg", f.mass_kg, 1e-6, 1e4));
  UH_CHECK(r.vec3(j, path, "center_of_mass", f.center_of_mass_body));
  UH_CHECK(r.number(j, path, "max_force_n", f.max_force_n, 1e-6, 1e4));
  UH_CHECK(r.number(j, path, "max_torque_nm", f.max_torque_nm, 1e-6, 1e3));
  return Ok{};
}

Status read_workspace(const FieldReader& r, const json& j, const std::string& path, WorkspaceMapping& w) {
  UH_CHECK(r.require_object(j, path));
  UH_CHECK(r.check_keys(j, path, {"scale", "offset", "rotation", "tool_offset"}));
  UH_CHECK(r.number(j, path, "scale", w.scale, 1e-6, 1e6));
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
    UH_CHECK(r.number(*it, p, "max_force_n", scene.safety_limits.max_force_n, 1e-6, 1e4));
    UH_CHECK(r.number(*it, p, "max_torque_nm", scene.safety_limits.max_torque_nm, 1e-6, 1e3));
    UH_CHECK(r.number(*it, p, "max_force_rate_n_per_s", scene.rate_limit.max_force_n_per_s, 1e-3, 1e9));
    UH_CHECK(r.number(*it, p, "max_torque_rate_nm_per_s", scene.rate_limit.max_torque_nm_per_s, 1e-3, 1e9));
    UH_CHECK(r.number(*it, p, "watchdog_max_age_s", o.safety.watchdog.max_age_s, 1e-4, 10.0));
    UH_CHECK(r.number(*it, p, "watchdog_ramp_s", o.safety.watchdog.ramp_s, 1e-4, 10.0));
  }
  if (const auto it = j.find("coupling"); it != j.end()) {
    const std::string p = FieldReader::join(path, "coupling");
    UH_CHECK(r.require_object(*it, p));
    UH_CHECK(r.check_keys(*it, p, {"enabled", "stiffness", "damping", "device_damping", "angular_stiffness",
                                   "angular_damping", "device_angular_damping", "passivity_margin", "proxy_mass_kg",
                                   "proxy_inertia_kg_m2"}));
    auto& c = o.coupling;
    UH_CHECK(r.boolean(*it, p, "enabled", o.use_coupling));
    UH_CHECK(r.number(*it, p, "stiffness", c.stiffness, 0.0, 1e7));
    UH_CHECK(r.number(*it, p, "damping", c.damping, 0.0, 1e5));
    UH_CHECK(r.number(*it, p, "device_damping", c.device_damping, 0.0, 1e5));
    UH_CHECK(r.number(*it, p, "angular_stiffness", c.angular_stiffness, 0.0, 1e5));
    UH_CHECK(r.number(*it, p, "angular_damping", c.angular_damping, 0.0, 1e5));
    UH_CHECK(r.number(*it, p, "device_angular_damping", c.device_angular_damping, 0.0, 1e5));
    UH_CHECK(r.number(*it, p, "passivity_margin", c.passivity_margin, 1e-3, 1.0));
    UH_CHECK(r.number(*it, p, "proxy_mass_kg", c.proxy_mass_kg, 1e-6, 1e4));
    UH_CHECK(r.number(*it, p, "proxy_inertia_kg_m2", c.proxy_inertia_kg_m2, 1e-12, 1e3));
  }
  if (const auto it = j.find("proxy"); it != j.end()) {
    const std::string p = FieldReader::join(path, "proxy");
    UH_CHECK(r.require_object(*it, p));
    UH_CHECK(r.check_keys(*it, p, {"enabled", "step_m", "penetration_m", "max_constraints", "smoothing_m"}));
    auto& x = o.proxy;
    UH_CHECK(r.boolean(*it, p, "enabled", x.enabled));
    UH_CHECK(r.number(*it, p, "step_m", x.step_m, 1e-5, 0.05));
    UH_CHECK(r.number(*it, p, "penetration_m", x.penetration_m, 0.0, 0.01));
    UH_CHECK(r.number(*it, p, "smoothing_m", x.smoothing_m, 0.0, 0.01));
    double capacity = x.max_constraints;
    UH_CHECK(r.number(*it, p, "max_constraints", capacity, 16.0, 1e6));
    x.max_constraints = static_cast<std::int32_t>(capacity);
    if (x.smoothing_m > x.step_m / 4)
      return r.error(FieldReader::join(p, "smoothing_m"),
                     fmt::format("{} m is more than a quarter of step_m ({} m): the pairs beyond the step are "
                                 "not in the smoothing's sum, so it would jump as they come and go",
                                 x.smoothing_m, x.step_m));
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
    UH_CHECK(r.number(j, path, "stiffness", m.stiffness, 1e-6, 1e12));
    m.has_stiffness = true;
  }
  if (j.contains("damping")) {
    UH_CHECK(r.number(j, path, "damping", m.damping, 0.0, 1e6));
    m.has_damping = true;
  }
  if (const auto it = j.find("friction"); it != j.end()) {
    const std::string p = FieldReader::join(path, "friction");
    UH_CHECK(r.require_object(*it, p));
    UH_CHECK(r.check_keys(*it, p, {"static", "dynamic"}));
    if (!it->contains("static") || !it->contains("dynamic"))
      return r.error(p,
                     "expected both 'static' (the coefficient at breakaway) and 'dynamic' (while sliding)");
    UH_CHECK(r.number(*it, p, "static", m.friction_static, 0.0, 10.0));
    UH_CHECK(r.number(*it, p, "dynamic", m.friction_dynamic, 0.0, 10.0));
    if (m.friction_dynamic > m.friction_static)
      return r.error(
          FieldReader::join(p, "dynamic"),
          fmt::format("is above 'static' ({} > {}): a sliding contact cannot hold more than a sticking one",
                      m.friction_dynamic, m.friction_static));
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
      UH_CHECK(r.number(*it, p, "period", period, 1e-5, 1.0));
      UH_CHECK(r.number(*it, p, "amplitude", amplitude, 0.0, 0.01));
      UH_CHECK(r.vec3(*it, p, "direction", direction));
      if (!(norm(direction) > 1e-9))
        return r.error(FieldReader::join(p, "direction"), "expected a non-zero [x, y, z]");
      m.texture = forcecomp::make_grating(period, amplitude, direction);
    } else if (type == "random") {
      UH_CHECK(r.check_keys(*it, p, {"type", "roughness", "correlation_length", "seed"}));
      if (!it->contains("roughness") || !it->contains("correlation_length"))
        return r.error(p, "a random texture needs 'roughness' [m] and 'correlation_length' [m]");
      double roughness = 0.0, length = 0.0;
      std::int64_t seed = 1;
      UH_CHECK(r.number(*it, p, "roughness", roughness, 0.0, 0.01));
      UH_CHECK(r.number(*it, p, "correlation_length", length, 1e-5, 1.0));
      UH_CHECK(r.integer(*it, p, "seed", seed, 0, std::int64_t{1} << 53));
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
    UH_CHECK(read_material_fields(r, value, FieldReader::join("materials", name), m));
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

// a material stiffness is the gradient law's k [N/m^2]: meaningless under the paper law
Status check_material_law(const FieldReader& r, const SceneTool& tool, const std::string& tool_path,
                          const std::string& path, const forcecomp::Material& m) {
  if (tool.force.law == forcecomp::ForceLaw::kPaper && m.has_stiffness)
    return r.error(
        FieldReader::join(path, "material.stiffness"),
        fmt::format("is the gradient law's stiffness [N/m^2]; this scene uses the paper law ({}.force.law)",
                    tool_path));
  return Ok{};
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
  UH_CHECK(check_material_law(r, tool, path, path, tool.material));
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
      for (const SceneTool& other : scene.tools)
        if (other.name == tool.name)
          return r.error(path + ".name", fmt::format("duplicate tool name '{}'", tool.name));
      scene.tools.push_back(std::move(tool));
    }
  }
  // names address objects and tools alike (the service's scene document, contact reports)
  for (std::size_t i = 0; i < scene.tools.size(); ++i)
    for (const SceneObject& o : scene.objects)
      if (o.name == scene.tools[i].name)
        return r.error(one != root.end() ? "tool.name" : fmt::format("tools[{}].name", i),
                       fmt::format("'{}' is also an object's name", o.name));
  for (std::size_t t = 0; t < scene.tools.size(); ++t)
    for (std::size_t i = 0; i < scene.objects.size(); ++i)
      UH_CHECK(check_material_law(r, scene.tools[t], one != root.end() ? "tool" : fmt::format("tools[{}]", t),
                                  fmt::format("objects[{}]", i), scene.objects[i].material));
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
  UH_CHECK(r.number(root, "", "seconds", scene.seconds, 0.0, 86400.0));
  if (const auto it = root.find("rates"); it != root.end()) {
    UH_CHECK(r.require_object(*it, "rates"));
    UH_CHECK(r.check_keys(*it, "rates", {"haptic_hz", "collision_hz"}));
    UH_CHECK(r.number(*it, "rates", "haptic_hz", scene.haptic_hz, 1.0, 10000.0));
    UH_CHECK(r.number(*it, "rates", "collision_hz", scene.collision_hz, 0.0, 10000.0));
  }

  if (const auto it = root.find("collision"); it != root.end()) {
    UH_CHECK(r.require_object(*it, "collision"));
    UH_CHECK(r.check_keys(*it, "collision", {"contact_margin", "coherence_skin"}));
    UH_CHECK(r.number(*it, "collision", "contact_margin", scene.contact_margin, 0.0, 1.0));
    UH_CHECK(r.number(*it, "collision", "coherence_skin", scene.coherence_skin, 0.0, 1.0));
  }

  const auto objects = root.find("objects");
  if (objects == root.end()) return r.error("objects", "missing (expected a list of objects)");
  if (!objects->is_array() || objects->empty()) return r.error("objects", "expected a non-empty list of objects");
  for (std::size_t i = 0; i < objects->size(); ++i) {
    const json& o = (*objects)[i];
    const std::string path = fmt::format("objects[{}]", i);
    UH_CHECK(r.require_object(o, path));
    UH_CHECK(r.check_keys(
        o, path,
        {"name", "mesh", "ist", "spheres", "max_sphere_radius", "meters_per_unit", "pose", "material"}));
    SceneObject object;
    UH_CHECK(r.string(o, path, "name", object.name, true));
    for (const auto& existing : scene.objects)
      if (existing.name == object.name) return r.error(path + ".name", fmt::format("duplicate object name '{}'", object.name));
    UH_CHECK(read_shape(r, o, path, base_dir, object.shape));
    UH_CHECK(r.pose(o, path, "pose", object.pose));
    UH_CHECK(read_material(r, o, path, materials, object.material));
    scene.objects.push_back(std::move(object));
  }

  UH_CHECK(read_tools(r, root, base_dir, materials, scene));

  if (const auto it = root.find("watch"); it != root.end()) {
    if (!it->is_array()) return r.error("watch", "expected a list of object names");
    for (std::size_t i = 0; i < it->size(); ++i) {
      const json& name = (*it)[i];
      const std::string path = fmt::format("watch[{}]", i);
      if (!name.is_string()) return r.error(path, "expected an object name");
      bool known = false;
      for (const auto& o : scene.objects) known = known || o.name == name.get<std::string>();
      if (!known) return r.error(path, fmt::format("no object is named '{}'", name.get<std::string>()));
      scene.watch.push_back(name.get<std::string>());
    }
  } else {
    for (const auto& o : scene.objects) scene.watch.push_back(o.name);
  }

  if (const auto it = root.find("force"); it != root.end()) UH_CHECK(read_force_options(r, *it, "force", scene));
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

std::filesystem::path default_cache_dir() {
  if (const char* dir = std::getenv("UH_CACHE_DIR"); dir != nullptr && *dir != '\0') return dir;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg != nullptr && *xdg != '\0')
    return std::filesystem::path(xdg) / "unrealhaptics";
  // Windows' per-user cache folder (set there, never on Linux)
  if (const char* local = std::getenv("LOCALAPPDATA"); local != nullptr && *local != '\0')
    return std::filesystem::path(local) / "unrealhaptics" / "cache";
  if (const char* home = std::getenv("HOME"); home != nullptr && *home != '\0')
    return std::filesystem::path(home) / ".cache" / "unrealhaptics";
  return std::filesystem::temp_directory_path() / "unrealhaptics-cache";
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

Result<ShapeTree> load_shape_tree(
    const SceneShape& shape, const std::filesystem::path& cache_dir,
    const std::function<void(const std::string& what, double fraction)>& progress) {
  if (shape.tree) return ShapeTree{shape.tree, shape.coverage};
  collette::IstAsset asset;
  if (!shape.ist.empty()) {
    auto loaded = collette::load_ist(shape.ist);
    if (!loaded) return loaded.error();
    asset = std::move(loaded).value();
  } else {
    auto hash = collette::hash_file(shape.mesh);
    if (!hash) return hash.error();
    std::error_code ec;
    std::filesystem::create_directories(cache_dir, ec);
    if (ec)
      return Error{fmt::format("{}: cannot create the cache folder: {}", cache_dir.string(), ec.message()),
                   ErrorKind::kFile};
    // keyed by everything the packing depends on (the radius bound in mesh units, shortest exact
    // form) and by the tree builder's version (a cache of an older builder's tree is rebuilt)
    const double max_radius = shape.max_sphere_radius / shape.meters_per_unit;
    const std::string bound = max_radius > 0.0 ? fmt::format("-r{}", max_radius) : std::string();
    const std::filesystem::path cached =
        cache_dir / fmt::format("{}-{:016x}-{}{}-t{}.ist", shape.mesh.stem().string(), *hash, shape.spheres,
                                bound, collette::kSphereTreeBuilderVersion);
    auto loaded = collette::load_ist(cached);
    if (loaded && loaded->meta.source_mesh_hash == *hash) {
      asset = std::move(loaded).value();
    } else {
      // absent, unreadable or stale: build it again (only the cache file is replaced)
      const std::string what = fmt::format("packing {} ({} spheres)", shape.mesh.filename().string(), shape.spheres);
      collette::IstBuildOptions options{
          .sphere_count = shape.spheres, .max_radius = max_radius, .meters_per_unit = shape.meters_per_unit};
      if (progress) options.progress = [&](double f) { progress(what, f); };
      auto built = collette::build_ist_asset(shape.mesh, options);
      if (!built) return built.error();
      if (auto saved = collette::save_ist(cached, built->asset); !saved) return saved.error();
      asset = std::move(built->asset);
    }
  }
  const double scale = shape.ist.empty() ? shape.meters_per_unit : asset.meta.meters_per_unit;
  return ShapeTree{
      std::make_shared<const collette::SphereTree>(collette::scale_sphere_tree(asset.tree, scale)),
      asset.meta.coverage};
}

Result<std::shared_ptr<const collette::MeshInside>> load_shape_surface(const SceneShape& shape) {
  if (shape.mesh.empty() || shape.tree) return std::shared_ptr<const collette::MeshInside>{};
  auto mesh = collette::load_mesh(shape.mesh);
  if (!mesh) return mesh.error();
  for (Vec3& v : mesh->vertices) v = v * shape.meters_per_unit;
  return std::make_shared<const collette::MeshInside>(*mesh);
}

}  // namespace uh::controllers
