#pragma once
/// \file
/// A force and a torque acting on one body.

#include <type_traits>

#include "uh/core/math.hpp"

namespace uh::forcecomp {

/// A force [N] and a torque [N m] acting on one body, both in the world frame; the torque is
/// about the body's centre of mass. Trivially copyable.
struct Wrench {
  Vec3 force{};   ///< [N], world frame
  Vec3 torque{};  ///< [N m], world frame, about the centre of mass
};
static_assert(std::is_trivially_copyable_v<Wrench>);

/// The motion of a rigid body at one instant, as needed for velocity-dependent (damping) forces.
/// A static body is the default value.
struct BodyMotion {
  Vec3 center_of_mass_world{};     ///< [L], world frame
  Vec3 linear_velocity_world{};    ///< velocity of the centre of mass [L/s], world frame
  Vec3 angular_velocity_world{};   ///< [rad/s], world frame

  /// Velocity [L/s] of the body-fixed point that is at `p_world` now. Real-time safe.
  constexpr Vec3 point_velocity(const Vec3& p_world) const {
    return linear_velocity_world + cross(angular_velocity_world, p_world - center_of_mass_world);
  }
};
static_assert(std::is_trivially_copyable_v<BodyMotion>);

}  // namespace uh::forcecomp
