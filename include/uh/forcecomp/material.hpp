#pragma once
/// \file
/// Haptic materials: what an object (or the tool) feels like besides its shape: stiffness,
/// damping, Coulomb friction and a surface texture; and how two materials combine where they meet.
/// Scene field `objects[].material` / `tool.material` (docs/scenes.md); rendered by SurfaceStage
/// (surface_stage.hpp) after the penalty force (docs/forcecomp.md, "Materials").

#include <array>
#include <cstdint>
#include <type_traits>

#include "uh/core/math.hpp"
#include "uh/forcecomp/force_params.hpp"

namespace uh::forcecomp {

/// Which texture a surface carries.
enum class TextureKind : std::uint8_t {
  kNone,     ///< smooth
  kGrating,  ///< periodic ridges: h(p) = amplitude sin(2 pi (direction . p) / period)
  kRandom,   ///< stationary random heights with Gaussian correlation (roughness, correlation_length)
};

/// A height field h(p) [m] over a body's surface, p in the body (mesh) frame [m]. The rendering
/// reads it as a change of the contact's depth (surface_stage.hpp). Trivially copyable: the
/// random texture's waves are drawn once, at setup (make_random_texture), never on the tick.
struct Texture {
  TextureKind kind = TextureKind::kNone;
  double period_m = 0.0;              ///< grating: distance between ridges [m], > 0
  double amplitude_m = 0.0;           ///< grating: peak height [m], >= 0
  Vec3 direction{1.0, 0.0, 0.0};      ///< grating: unit wave direction (across the ridges), body frame
  double roughness_m = 0.0;           ///< random: RMS height [m], >= 0
  double correlation_length_m = 0.0;  ///< random: l in the correlation exp(-r^2 / (2 l^2)) [m], > 0
  std::uint64_t seed = 0;             ///< random: which realisation

  /// Random texture: h(p) = roughness sqrt(2 / kWaves) sum_i cos(k_i . p + phase_i), with the
  /// wave vectors k_i drawn from N(0, I / l^2) and the phases uniform: a stationary field of RMS
  /// `roughness` whose correlation is roughness^2 exp(-r^2 / (2 l^2)) (the mean of cos(k . r) over
  /// that Gaussian), Gaussian in its one-point distribution as kWaves grows.
  static constexpr int kWaves = 64;
  struct Wave {
    Vec3 wave_vector{};  ///< [rad / m]
    double phase = 0.0;  ///< [rad]
  };
  std::array<Wave, kWaves> waves{};
};
static_assert(std::is_trivially_copyable_v<Texture>);

/// The height of `texture` at body-frame point p [m]. Real-time safe: O(1) for a grating,
/// O(kWaves) for a random texture.
double texture_height(const Texture& texture, const Vec3& p_body);

/// The largest |h| the texture can reach [m] (for bounds and plots).
double texture_peak_height(const Texture& texture);

/// A grating of `period_m` and peak height `amplitude_m` across `direction` (normalised here).
Texture make_grating(double period_m, double amplitude_m, const Vec3& direction);

/// A random texture of RMS height `roughness_m` and correlation length `correlation_length_m`,
/// its waves drawn from `seed` (the same seed gives the same surface on every platform).
Texture make_random_texture(double roughness_m, double correlation_length_m, std::uint64_t seed);

/// One surface's material as a scene gives it: every field optional, so that an object without a
/// material feels exactly as it did before materials existed.
struct Material {
  bool has_stiffness = false;
  double stiffness = 0.0;  ///< gradient law's k [N/m^2] for contacts with this surface
  bool has_damping = false;
  double damping = 0.0;  ///< eps_d [N s/m]
  bool has_friction = false;
  double friction_static = 0.0;   ///< Coulomb coefficient at breakaway, >= friction_dynamic
  double friction_dynamic = 0.0;  ///< Coulomb coefficient while sliding, >= 0
  Texture texture{};
};

/// What one (object, tool) contact renders: the two materials combined (combine_materials).
struct ContactMaterial {
  double stiffness = 2.0e4;  ///< k [N/m^2] of the penalty law for this contact
  double damping = 0.0;      ///< eps_d [N s/m]
  double friction_static = 0.0;
  double friction_dynamic = 0.0;
  Texture object_texture{};  ///< in the object's frame
  Texture tool_texture{};    ///< in the tool's frame

  bool has_friction() const { return friction_static > 0.0 || friction_dynamic > 0.0; }
  bool has_texture() const {
    return object_texture.kind != TextureKind::kNone || tool_texture.kind != TextureKind::kNone;
  }
};
static_assert(std::is_trivially_copyable_v<ContactMaterial>);

/// The combination rules (docs/forcecomp.md, "Materials"). A property only one side gives is that
/// side's; the tool's force parameters (`tool.force.stiffness`, `damping`) stand in for an object
/// that gives no stiffness or damping, so a scene without materials feels as before.
///  - stiffness: the two surfaces are springs in series, k = k_o k_t / (k_o + k_t);
///  - damping: the dampers add, eps_d = eps_o + eps_t;
///  - friction: each coefficient is the geometric mean sqrt(mu_o mu_t) (Box2D's rule: a
///    frictionless side makes the contact frictionless);
///  - texture: both surfaces' heights add, each in its own body frame.
ContactMaterial combine_materials(const Material& object, const Material& tool,
                                  const ForceParams& tool_force);

}  // namespace uh::forcecomp
