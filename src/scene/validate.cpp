#include "uh/scene/validate.hpp"

#include <algorithm>
#include <cmath>
#include <system_error>

#include <fmt/format.h>

#include "uh/core/regular_file.hpp"

namespace uh::scene {
namespace {

Error invalid(const std::string& path, const std::string& what) {
  return Error{fmt::format("field '{}': {}", path, what), ErrorKind::kInvalid};
}

std::string join(const std::string& path, const char* key) {
  return path.empty() ? std::string(key) : fmt::format("{}.{}", path, key);
}

// A number in [min, max] (the message the scene file's readers have always given).
Status in_range(const std::string& path, double v, double min, double max) {
  if (!std::isfinite(v) || v < min || v > max)
    return invalid(path, fmt::format("expected a number in [{}, {}], got {}", min, max, v));
  return Ok{};
}

// A limit: in [min, max], or haptico::kNoLimit (+inf) for none (never written in a file).
Status limit_in_range(const std::string& path, double v, double min, double max) {
  if (v == haptico::kNoLimit) return Ok{};
  return in_range(path, v, min, max);
}

Status whole_in_range(const std::string& path, std::int64_t v, std::int64_t min, std::int64_t max) {
  if (v < min || v > max) return invalid(path, fmt::format("expected a whole number in [{}, {}], got {}", min, max, v));
  return Ok{};
}

Status finite(const std::string& path, const Vec3& v) {
  if (!is_finite(v)) return invalid(path, "expected finite numbers");
  return Ok{};
}

Status unit_rotation(const std::string& path, const Quat& q) {
  const double n = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
  if (!std::isfinite(n) || std::abs(n - 1.0) > 1e-6) return invalid(path, "expected a unit quaternion [w, x, y, z]");
  return Ok{};
}

Status pose(const std::string& path, const Pose& p) {
  if (Status s = finite(join(path, "position"), p.position); !s) return s;
  return unit_rotation(join(path, "rotation"), p.rotation);
}

// a mesh or .ist is refused when the scene is checked, not when it is packed: a directory, FIFO
// or device would otherwise surface as a packing error much later
Status regular_file(const std::string& path, const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) return invalid(path, fmt::format("file not found: {}", file.string()));
  if (auto checked = check_regular_file(file, kMaxMeshFileBytes); !checked)
    return invalid(path, checked.error().message);
  return Ok{};
}

#define UH_VALIDATE(expr)                  \
  do {                                     \
    if (Status s_ = (expr); !s_) return s_; \
  } while (false)

Status validate_texture(const forcecomp::Texture& t, const std::string& path) {
  switch (t.kind) {
    case forcecomp::TextureKind::kNone:
      return Ok{};
    case forcecomp::TextureKind::kGrating:
      UH_VALIDATE(in_range(join(path, "period"), t.period_m, 1e-5, 1.0));
      UH_VALIDATE(in_range(join(path, "amplitude"), t.amplitude_m, 0.0, 0.01));
      if (!(std::abs(norm(t.direction) - 1.0) < 1e-6)) return invalid(join(path, "direction"), "expected a non-zero [x, y, z]");
      return Ok{};
    case forcecomp::TextureKind::kRandom:
      UH_VALIDATE(in_range(join(path, "roughness"), t.roughness_m, 0.0, 0.01));
      return in_range(join(path, "correlation_length"), t.correlation_length_m, 1e-5, 1.0);
  }
  return invalid(join(path, "type"), "expected \"grating\" or \"random\"");
}

Status validate_force_params(const forcecomp::ForceParams& f, const std::string& path) {
  UH_VALIDATE(in_range(join(path, "stiffness"), f.stiffness, 0.0, 1e12));
  UH_VALIDATE(in_range(join(path, "force_scale"), f.force_scale, 0.0, 1e15));
  UH_VALIDATE(in_range(join(path, "damping"), f.damping, 0.0, 1e6));
  UH_VALIDATE(in_range(join(path, "damping_full_volume"), f.damping_full_volume, 0.0, 1.0));
  UH_VALIDATE(in_range(join(path, "mass_kg"), f.mass_kg, 1e-6, 1e4));
  UH_VALIDATE(finite(join(path, "center_of_mass"), f.center_of_mass_body));
  UH_VALIDATE(in_range(join(path, "max_force_n"), f.max_force_n, 1e-6, 1e4));
  return in_range(join(path, "max_torque_nm"), f.max_torque_nm, 1e-6, 1e3);
}

Status validate_workspace(const WorkspaceMapping& w, const std::string& path) {
  UH_VALIDATE(in_range(join(path, "scale"), w.scale, 1e-6, 1e6));
  UH_VALIDATE(finite(join(path, "offset"), w.world_from_device_base.position));
  UH_VALIDATE(unit_rotation(join(path, "rotation"), w.world_from_device_base.rotation));
  return finite(join(path, "tool_offset"), w.handle_from_tool.position);
}

// a material stiffness is the gradient law's k [N/m^2]: meaningless under the paper law
Status check_material_law(const SceneTool& tool, const std::string& tool_path, const std::string& material_path,
                          const forcecomp::Material& m) {
  if (tool.force.law == forcecomp::ForceLaw::kPaper && m.has_stiffness)
    return invalid(join(material_path, "stiffness"),
                   fmt::format("is the gradient law's stiffness [N/m^2]; this scene uses the paper law ({}.force.law)",
                               tool_path));
  return Ok{};
}

Status validate_safety(const Scene& scene) {
  const std::string p = "force.safety";
  UH_VALIDATE(limit_in_range(join(p, "max_force_n"), scene.safety_limits.max_force_n, 1e-6, 1e4));
  UH_VALIDATE(limit_in_range(join(p, "max_torque_nm"), scene.safety_limits.max_torque_nm, 1e-6, 1e3));
  UH_VALIDATE(limit_in_range(join(p, "max_force_rate_n_per_s"), scene.rate_limit.max_force_n_per_s, 1e-3, 1e9));
  UH_VALIDATE(limit_in_range(join(p, "max_torque_rate_nm_per_s"), scene.rate_limit.max_torque_nm_per_s, 1e-3, 1e9));
  UH_VALIDATE(in_range(join(p, "watchdog_max_age_s"), scene.force.safety.watchdog.max_age_s, 1e-4, 10.0));
  return in_range(join(p, "watchdog_ramp_s"), scene.force.safety.watchdog.ramp_s, 1e-4, 10.0);
}

Status validate_coupling(const forcecomp::VirtualCouplingOptions& c) {
  const std::string p = "force.coupling";
  UH_VALIDATE(in_range(join(p, "stiffness"), c.stiffness, 0.0, 1e7));
  UH_VALIDATE(in_range(join(p, "damping"), c.damping, 0.0, 1e5));
  UH_VALIDATE(in_range(join(p, "device_damping"), c.device_damping, 0.0, 1e5));
  if (c.angular_stiffness) UH_VALIDATE(in_range(join(p, "angular_stiffness"), *c.angular_stiffness, 0.0, 1e5));
  UH_VALIDATE(in_range(join(p, "angular_damping"), c.angular_damping, 0.0, 1e5));
  UH_VALIDATE(in_range(join(p, "device_angular_damping"), c.device_angular_damping, 0.0, 1e5));
  UH_VALIDATE(in_range(join(p, "passivity_margin"), c.passivity_margin, 1e-3, 1.0));
  UH_VALIDATE(in_range(join(p, "proxy_mass_kg"), c.proxy_mass_kg, 1e-6, 1e4));
  return in_range(join(p, "proxy_inertia_kg_m2"), c.proxy_inertia_kg_m2, 1e-12, 1e3);
}

Status validate_proxy(const ForceControllerOptions& o) {
  const std::string p = "force.proxy";
  const ToolProxyOptions& x = o.proxy;
  UH_VALIDATE(in_range(join(p, "step_m"), x.step_m, 1e-5, 0.05));
  UH_VALIDATE(in_range(join(p, "penetration_m"), x.penetration_m, 0.0, 0.01));
  UH_VALIDATE(in_range(join(p, "smoothing_m"), x.smoothing_m, 0.0, 0.01));
  UH_VALIDATE(in_range(join(p, "max_constraints"), x.max_constraints, 16.0, 1e6));
  if (x.smoothing_m > x.step_m / 4)
    return invalid(join(p, "smoothing_m"),
                   fmt::format("{} m is more than a quarter of step_m ({} m): the pairs beyond the step are not in "
                               "the smoothing's sum, so it would jump as they come and go",
                               x.smoothing_m, x.step_m));
  if (x.enabled && o.use_coupling)
    return invalid(p, "the proxy and force.coupling (the simulated tool of the penalty path) exclude each other");
  return Ok{};
}

Status validate_names(const Scene& scene) {
  for (std::size_t i = 0; i < scene.objects.size(); ++i) {
    const std::string path = fmt::format("objects[{}].name", i);
    if (scene.objects[i].name.empty()) return invalid(path, "missing (expected a non-empty string)");
    for (std::size_t j = 0; j < i; ++j)
      if (scene.objects[j].name == scene.objects[i].name)
        return invalid(path, fmt::format("duplicate object name '{}'", scene.objects[i].name));
  }
  for (std::size_t t = 0; t < scene.tools.size(); ++t) {
    const std::string path = join(tool_path(scene, t), "name");
    for (std::size_t u = 0; u < t; ++u)
      if (scene.tools[u].name == scene.tools[t].name)
        return invalid(path, fmt::format("duplicate tool name '{}'", scene.tools[t].name));
    // names address objects and tools alike (the service's scene document, contact reports)
    for (const SceneObject& o : scene.objects)
      if (o.name == scene.tools[t].name) return invalid(path, fmt::format("'{}' is also an object's name", o.name));
  }
  for (std::size_t i = 0; i < scene.watch.size(); ++i) {
    const bool known = std::any_of(scene.objects.begin(), scene.objects.end(),
                                   [&](const SceneObject& o) { return o.name == scene.watch[i]; });
    if (!known) return invalid(fmt::format("watch[{}]", i), fmt::format("no object is named '{}'", scene.watch[i]));
  }
  return Ok{};
}

}  // namespace

std::string tool_path(const Scene& scene, std::size_t index) {
  return scene.tools.size() > 1 ? fmt::format("tools[{}]", index) : std::string("tool");
}

Status validate_rates(double haptic_hz, double collision_hz) {
  UH_VALIDATE(in_range("rates.haptic_hz", haptic_hz, 1.0, 10000.0));
  return in_range("rates.collision_hz", collision_hz, 0.0, 10000.0);
}

Status validate_shape(const SceneShape& shape, const std::string& path) {
  // a tree in memory is used as it is: the mesh or .ist it may have come from is not read again
  if (!shape.tree) {
    if (shape.mesh.empty() == shape.ist.empty())
      return invalid(path, "give exactly one of 'mesh' (a mesh file, packed on first use) or 'ist' (a .ist file)");
    if (!shape.mesh.empty()) UH_VALIDATE(regular_file(join(path, "mesh"), shape.mesh));
    if (!shape.ist.empty()) UH_VALIDATE(regular_file(join(path, "ist"), shape.ist));
  }
  UH_VALIDATE(whole_in_range(join(path, "spheres"), shape.spheres, 1, 2'000'000));
  UH_VALIDATE(in_range(join(path, "meters_per_unit"), shape.meters_per_unit, 1e-9, 1e6));
  // 0 = unbounded (the default)
  if (shape.max_sphere_radius != 0.0) {
    if (!shape.ist.empty())
      return invalid(join(path, "max_sphere_radius"), "applies only when packing a 'mesh' (a .ist file is packed already)");
    UH_VALIDATE(in_range(join(path, "max_sphere_radius"), shape.max_sphere_radius, 1e-9, 1e6));
  }
  if (shape.tree && !(shape.coverage > 0.0 && shape.coverage <= 1.0))
    return invalid(join(path, "coverage"), fmt::format("expected a number in (0, 1], got {}", shape.coverage));
  return Ok{};
}

Status validate_material(const forcecomp::Material& m, const std::string& path) {
  if (m.has_stiffness) UH_VALIDATE(in_range(join(path, "stiffness"), m.stiffness, 1e-6, 1e12));
  if (m.has_damping) UH_VALIDATE(in_range(join(path, "damping"), m.damping, 0.0, 1e6));
  if (m.has_friction) {
    const std::string p = join(path, "friction");
    UH_VALIDATE(in_range(join(p, "static"), m.friction_static, 0.0, 10.0));
    UH_VALIDATE(in_range(join(p, "dynamic"), m.friction_dynamic, 0.0, 10.0));
    if (m.friction_dynamic > m.friction_static)
      return invalid(join(p, "dynamic"),
                     fmt::format("is above 'static' ({} > {}): a sliding contact cannot hold more than a sticking one",
                                 m.friction_dynamic, m.friction_static));
  }
  return validate_texture(m.texture, join(path, "texture"));
}

namespace {

Status validate_deformable(const SceneObject& object, const std::string& path) {
  const SceneDeformable& d = *object.deformable;
  // the volume is meshed around the mesh's inside: a .ist alone has no surface to mesh
  if (object.shape.mesh.empty())
    return invalid(path, "a deformable object needs a 'mesh' (its volume is meshed from the mesh's inside)");
  UH_VALIDATE(in_range(join(path, "young_modulus_pa"), d.young_modulus_pa, 10.0, 1e10));
  UH_VALIDATE(in_range(join(path, "poisson_ratio"), d.poisson_ratio, 0.0, 0.49));
  UH_VALIDATE(in_range(join(path, "density_kg_m3"), d.density_kg_m3, 1.0, 1e5));
  UH_VALIDATE(in_range(join(path, "damping"), d.damping, 0.0, 1.0));
  // 0 (or the field left out): chosen from the object's size
  if (d.tetrahedra != 0) UH_VALIDATE(whole_in_range(join(path, "tetrahedra"), d.tetrahedra, 6, 200'000));
  UH_VALIDATE(in_range(join(path, "rate_hz"), d.rate_hz, 10.0, 2000.0));
  if (!d.fixed_box) return Ok{};
  const std::string box = join(path, "fixed.box");
  UH_VALIDATE(finite(box + "[0]", d.fixed_box->min));
  UH_VALIDATE(finite(box + "[1]", d.fixed_box->max));
  const Vec3& a = d.fixed_box->min;
  const Vec3& b = d.fixed_box->max;
  if (a.x > b.x || a.y > b.y || a.z > b.z)
    return invalid(box, "expected [[x0, y0, z0], [x1, y1, z1]] with x0 <= x1, y0 <= y1 and z0 <= z1");
  return Ok{};
}

}  // namespace

Status validate_object(const SceneObject& object, const std::string& path) {
  UH_VALIDATE(validate_shape(object.shape, path));
  UH_VALIDATE(pose(join(path, "pose"), object.pose));
  if (object.deformable) UH_VALIDATE(validate_deformable(object, join(path, "deformable")));
  return validate_material(object.material, join(path, "material"));
}

Status validate_tool(const SceneTool& tool, const std::string& path) {
  if (tool.name.empty()) return invalid(join(path, "name"), "expected a non-empty string");
  UH_VALIDATE(validate_shape(tool.shape, path));
  UH_VALIDATE(validate_force_params(tool.force, join(path, "force")));
  UH_VALIDATE(validate_material(tool.material, join(path, "material")));
  UH_VALIDATE(check_material_law(tool, path, join(path, "material"), tool.material));
  if (tool.device.driver.empty()) return invalid(join(path, "device.driver"), "missing (expected a string)");
  return validate_workspace(tool.workspace, join(path, "workspace"));
}

Status validate(const Scene& scene) {
  UH_VALIDATE(in_range("seconds", scene.seconds, 0.0, 86400.0));
  UH_VALIDATE(validate_rates(scene.haptic_hz, scene.collision_hz));
  UH_VALIDATE(in_range("collision.contact_margin", scene.contact_margin, 0.0, 1.0));
  UH_VALIDATE(in_range("collision.coherence_skin", scene.coherence_skin, 0.0, 1.0));
  if (scene.tools.empty()) return invalid("tool", "missing (the scene has no tool)");
  if (scene.objects.empty()) return invalid("objects", "expected a non-empty list of objects");
  for (std::size_t i = 0; i < scene.objects.size(); ++i)
    UH_VALIDATE(validate_object(scene.objects[i], fmt::format("objects[{}]", i)));
  for (std::size_t t = 0; t < scene.tools.size(); ++t) {
    const std::string path = tool_path(scene, t);
    UH_VALIDATE(validate_tool(scene.tools[t], path));
    for (std::size_t i = 0; i < scene.objects.size(); ++i)
      UH_VALIDATE(check_material_law(scene.tools[t], path, fmt::format("objects[{}].material", i),
                                     scene.objects[i].material));
  }
  UH_VALIDATE(validate_names(scene));
  UH_VALIDATE(validate_safety(scene));
  UH_VALIDATE(validate_coupling(scene.force.coupling));
  return validate_proxy(scene.force);
}

}  // namespace uh::scene
