#pragma once
/// \file
/// ForceComponent: the force-computing part of one object (the paper's ForceComp component).

#include <span>

#include "uh/core/contact.hpp"
#include "uh/core/math.hpp"
#include "uh/forcecomp/contact_patches.hpp"
#include "uh/forcecomp/force_params.hpp"
#include "uh/forcecomp/penalty_force.hpp"

namespace uh::forcecomp {

class HeldContactSet;

/// Options of a ForceComponent (options aggregate).
struct ForceComponentOptions {
  ForceParams params{};
  ForceMode mode = ForceMode::k6Dof;
  ContactSide side = ContactSide::kB;  ///< which object of the contact frames this component is
};

/// Computes the volumetric penalty force and torque on one object (the tool) from collision results.
///
/// Holds only parameters: it is a value type, cheap to copy, and its const methods may be called
/// from any thread (typically the haptic thread). All methods are real-time safe. It applies no
/// limits: pass its result through ForceSafety (NaN guard, watchdog) and let the haptic manager's
/// limit chain (haptico::ForceLimiter) bound it.
class ForceComponent {
 public:
  ForceComponent() = default;
  explicit ForceComponent(const ForceComponentOptions& options) : options_(options) {}

  const ForceComponentOptions& options() const { return options_; }
  const ForceParams& params() const { return options_.params; }

  /// The motion of this object given its pose (world_from_body), the velocity of its body origin
  /// [L/s] and its angular velocity [rad/s], all world frame: places the centre of mass and shifts
  /// the velocity to it.
  BodyMotion body_motion(const Pose& world_from_body, const Vec3& origin_velocity_world,
                         const Vec3& angular_velocity_world) const;

  /// Force and torque on this object from a pair list with world-frame normals and centroids.
  /// `other` is the other object's motion (default: static). `coverage_product` is c_A c_B of the
  /// two packings (PenaltyInput::coverage_product; 1: uncalibrated), which the gradient law divides by.
  PenaltyResult evaluate(std::span<const SpherePairContact> pairs, const BodyMotion& self,
                         const BodyMotion& other = {}, double coverage_product = 1.0) const;
  /// Same from a whole ContactFrame (at the poses the query used).
  PenaltyResult evaluate(const ContactFrame& frame, const BodyMotion& self, const BodyMotion& other = {},
                         double coverage_product = 1.0) const;
  /// Multi-rate: re-evaluates a held pair set at the current poses of A and B and computes the
  /// force (HeldContactSet::evaluate; of one patch's pairs with a `selection`). `held` is not
  /// const: it writes its preallocated scratch.
  PenaltyResult evaluate(HeldContactSet& held, const Pose& world_from_a, const Pose& world_from_b,
                         const BodyMotion& self, const BodyMotion& other = {}, double coverage_product = 1.0,
                         const PatchSelection& selection = {}) const;

  /// The PenaltyInput this component uses for the given motions and packings.
  PenaltyInput penalty_input(const BodyMotion& self, const BodyMotion& other,
                             double coverage_product = 1.0) const;

 private:
  ForceComponentOptions options_{};
};

}  // namespace uh::forcecomp
