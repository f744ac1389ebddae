#pragma once
/// \file
/// SurfaceStage: friction and texture of one contact, rendered after the penalty force on the
/// haptic tick (docs/forcecomp.md, "Materials").
///
/// One contact is one contact patch (contact_patches.hpp), a connected region of the overlap, fed
/// that patch's penalty wrench: a tool touching an object in two places has two stages, so that
/// the friction is mu (N1 + N2), not mu |N1 + N2| (ForceController keeps one per patch).
///
/// It reads the penalty wrench of the contact (whatever computed it: a collision frame, the held
/// pairs re-evaluated, a linearised model) and a little contact geometry (ContactGeometry: the
/// normal, a point of the tool at the contact, a depth estimate) and adds:
///
/// Friction (Coulomb, stick-slip). A stick point (the proxy) sits on the object's surface, in the
/// object's frame. The tangential force is a spring of `stick_stiffness` from the tool's contact
/// point to the stick point, in the tangent plane; while it stays within mu_s N (the friction
/// cone at breakaway) the stick point stays put, so a tool held still on a slope does not slide.
/// Beyond, the contact slips: the stick point is dragged behind the tool so that the spring pulls
/// with mu_d N, until the spring relaxes below mu_d N and the contact sticks again. The stick
/// point only ever moves towards the tool, so friction only stores energy in the spring or
/// dissipates it: it never creates energy (the spring is within the sampled-data passivity bound
/// when stick_stiffness < 2 b / T, virtual_coupling.hpp).
///
/// Texture. The object's (and the tool's) texture height h at the contact point, each read in
/// its own body frame at the current pose (so the spatial frequency is right at any speed), is a
/// change of the contact's depth: the normal force is scaled by (depth + h) / depth, the local
/// spring of the contact, with h / depth clamped to +-`max_texture_share` (the force never
/// reverses). The texture's energy is observed (the work of its force, held over each period, on
/// the contact point's motion); the texture may do positive work only out of the energy it has
/// taken out of the hand before, beyond that its force is scaled down (to zero without credit): it
/// never puts net energy into the hand (a passivity observer and controller, Hannaford and Ryu 2002).
///
/// Real-time safe: no allocation, lock, throw or log; O(1) (O(Texture::kWaves) for random textures).

#include <cstdint>

#include "uh/core/math.hpp"
#include "uh/forcecomp/material.hpp"
#include "uh/forcecomp/wrench.hpp"

namespace uh::forcecomp {

/// Settings of a SurfaceStage (options aggregate).
struct SurfaceStageOptions {
  /// Stiffness of the stick-point spring [N/m]: how far a sticking contact gives (mu_s N / k) before
  /// it slips. Keep it below the passivity bound 2 b / T of the device (2000 N/m for b = 1 N s/m at 1 kHz).
  double stick_stiffness = 500.0;
  /// The largest relative change of the normal force a texture makes, |h / depth| <= this, in [0, 1).
  double max_texture_share = 0.5;
  /// Smallest depth estimate used [m] (a contact just touching has no meaningful depth).
  double min_depth_m = 2.0e-4;
  /// k3Dof adds no torque (the friction and texture forces act at the contact point in 6-DOF).
  ForceMode mode = ForceMode::k6Dof;
};

/// What the stage needs about one contact besides its penalty wrench; world frame.
struct ContactGeometry {
  Vec3 normal_world{};       ///< unit normal out of the object (where the penalty pushes the tool)
  Vec3 point_world{};        ///< the contact point, a point fixed on the tool [m]
  double depth_m = 0.0;      ///< penetration estimate [m]
  Pose world_from_object{};  ///< the object's pose now
  Pose world_from_tool{};    ///< the tool's pose now
};

/// What the stage added this tick.
struct SurfaceResult {
  Wrench wrench{};  ///< penalty + friction + texture, on the tool, torque about its centre of mass
  Wrench added{};   ///< friction + texture alone (wrench - penalty, without its rounding)
  Vec3 friction_force_world{};  ///< the friction part [N]
  Vec3 texture_force_world{};   ///< the texture part [N]
  double normal_force_n = 0.0;  ///< N: the penalty force along the normal [N]
  bool sliding = false;         ///< the contact slips this tick
};

/// The friction and texture of one (object, tool) contact. Haptic thread only, after construction.
class SurfaceStage {
 public:
  SurfaceStage() = default;
  explicit SurfaceStage(const ContactMaterial& material, const SurfaceStageOptions& options = {});

  /// True when the material has friction or texture (else apply() returns the penalty unchanged).
  bool active() const { return material_.has_friction() || material_.has_texture(); }

  /// Adds friction and texture to `penalty` (the penalty wrench on the tool, world frame, torque
  /// about `tool_center_of_mass_world`). A zero penalty force ends the contact (the stick point is
  /// placed anew at the next touch). Real-time safe.
  SurfaceResult apply(const Wrench& penalty, const ContactGeometry& contact,
                      const Vec3& tool_center_of_mass_world);

  /// The contact point moved on the tool (a new collision result placed it elsewhere) by
  /// `delta_world` at the current pose: the stick point moves with it, so the jump is not felt
  /// as a slide.
  void shift_contact_point(const Vec3& delta_world, const Pose& world_from_object);

  /// Forgets the contact (the next apply() starts a new stick point).
  void reset();

  /// Work the texture force has done on the contact point so far [J] (<= one tick's work above 0).
  double texture_work_j() const { return texture_work_j_; }
  /// Ticks in which the passivity controller scaled the texture force down.
  std::uint64_t texture_drops() const { return texture_drops_; }
  const ContactMaterial& material() const { return material_; }

 private:
  ContactMaterial material_{};
  SurfaceStageOptions options_{};
  bool touching_ = false;
  bool sticking_ = true;
  Vec3 stick_point_object_{};  // the proxy, object frame [m]
  Vec3 last_point_world_{};    // the contact point at the last tick [m]
  Vec3 last_texture_force_{};  // the texture force held since the last tick [N]
  double texture_work_j_ = 0.0;
  std::uint64_t texture_drops_ = 0;
};

}  // namespace uh::forcecomp
