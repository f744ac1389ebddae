#pragma once
// The documented range of each numeric scene field (docs/scenes.md), as the scene file names it:
// the table the rule tests hold the file parser, validate(), the session and the C API's setters
// to, each refusing a value just outside with the same message.

#include <array>
#include <cstdint>
#include <string>

#include <fmt/format.h>

namespace uh::scene::testing {

struct FieldRange {
  const char* path;  ///< as in the scene file (one tool, one object)
  double min;
  double max;
  bool whole = false;  ///< a whole number ("expected a whole number in ...")
};

inline constexpr std::array kFieldRanges{
    FieldRange{"seconds", 0.0, 86400.0},
    FieldRange{"rates.haptic_hz", 1.0, 10000.0},
    FieldRange{"rates.collision_hz", 0.0, 10000.0},
    FieldRange{"collision.contact_margin", 0.0, 1.0},
    FieldRange{"collision.coherence_skin", 0.0, 1.0},
    FieldRange{"objects[0].spheres", 1.0, 2000000.0, true},
    FieldRange{"objects[0].meters_per_unit", 1e-9, 1e6},
    FieldRange{"objects[0].max_sphere_radius", 1e-9, 1e6},
    FieldRange{"objects[0].material.stiffness", 1e-6, 1e12},
    FieldRange{"objects[0].material.damping", 0.0, 1e6},
    FieldRange{"objects[0].deformable.young_modulus_pa", 10.0, 1e10},
    FieldRange{"objects[0].deformable.poisson_ratio", 0.0, 0.49},
    FieldRange{"objects[0].deformable.density_kg_m3", 1.0, 1e5},
    FieldRange{"objects[0].deformable.damping", 0.0, 1.0},
    FieldRange{"objects[0].deformable.tetrahedra", 6.0, 200000.0, true},
    FieldRange{"objects[0].deformable.rate_hz", 10.0, 2000.0},
    FieldRange{"tool.spheres", 1.0, 2000000.0, true},
    FieldRange{"tool.meters_per_unit", 1e-9, 1e6},
    FieldRange{"tool.force.stiffness", 0.0, 1e12},
    FieldRange{"tool.force.damping", 0.0, 1e6},
    FieldRange{"tool.force.damping_full_volume", 0.0, 1.0},
    FieldRange{"tool.force.mass_kg", 1e-6, 1e4},
    FieldRange{"tool.force.max_force_n", 1e-6, 1e4},
    FieldRange{"tool.force.max_torque_nm", 1e-6, 1e3},
    FieldRange{"tool.workspace.scale", 1e-6, 1e6},
    FieldRange{"force.safety.max_force_n", 1e-6, 1e4},
    FieldRange{"force.safety.max_torque_nm", 1e-6, 1e3},
    FieldRange{"force.safety.max_force_rate_n_per_s", 1e-3, 1e9},
    FieldRange{"force.safety.max_torque_rate_nm_per_s", 1e-3, 1e9},
    FieldRange{"force.safety.watchdog_max_age_s", 1e-4, 10.0},
    FieldRange{"force.safety.watchdog_ramp_s", 1e-4, 10.0},
    FieldRange{"force.coupling.stiffness", 0.0, 1e7},
    FieldRange{"force.coupling.damping", 0.0, 1e5},
    FieldRange{"force.coupling.passivity_margin", 1e-3, 1.0},
    FieldRange{"force.coupling.proxy_mass_kg", 1e-6, 1e4},
    FieldRange{"force.proxy.step_m", 1e-5, 0.05},
    FieldRange{"force.proxy.penetration_m", 0.0, 0.01},
};

/// Just below the range and just above it (a whole number's neighbours for whole fields).
inline double below(const FieldRange& f) { return f.whole ? f.min - 1.0 : (f.min > 0.0 ? f.min / 2.0 : -f.max / 1000.0); }
inline double above(const FieldRange& f) { return f.whole ? f.max + 1.0 : f.max * 2.0; }

/// The message every checker gives for `value` in field `f`.
inline std::string range_message(const FieldRange& f, double value) {
  if (f.whole)
    return fmt::format("field '{}': expected a whole number in [{}, {}], got {}", f.path,
                       static_cast<std::int64_t>(f.min), static_cast<std::int64_t>(f.max),
                       static_cast<std::int64_t>(value));
  return fmt::format("field '{}': expected a number in [{}, {}], got {}", f.path, f.min, f.max, value);
}

}  // namespace uh::scene::testing
