#pragma once
/// \file
/// VirtualCoupling: a spring-damper between the device handle and a simulated tool (proxy), with
/// its stiffness bounded by the sampled-data passivity condition.

#include <optional>

#include "uh/core/math.hpp"
#include "uh/forcecomp/wrench.hpp"

namespace uh::forcecomp {

/// The largest coupling stiffness K [N/m] for which a spring K with damper B [N s/m], rendered at
/// period T [s] on a device with physical damping b [N s/m], stays passive (Colgate): the
/// condition is b > K T / 2 + |B|, so the bound is K < 2 (b - |B|) / T. Returns 0 when b <= |B|
/// or T <= 0 or an input is not finite (no stiffness is provably passive then). The same form
/// holds for rotation with b, B in N m s/rad and K in N m/rad. E.g. b = 1 N s/m, T = 1 ms, B = 0:
/// 2000 N/m (2 N/mm); at 4 kHz: 8000 N/m. Real-time safe.
double max_passive_stiffness(double device_damping, double period_s, double coupling_damping);

/// Options of a VirtualCoupling (options aggregate). Linear quantities in metres, N and seconds.
struct VirtualCouplingOptions {
  double stiffness = 1500.0;             ///< K requested [N/m]; clamped to margin * bound
  double damping = 0.0;                  ///< B of the coupling damper [N s/m], >= 0
  double device_damping = 1.0;           ///< b, the device's physical damping [N s/m]
  /// K_r requested [N m/rad], clamped to margin * the rotational bound; 0 disables the rotational
  /// coupling (3-DOF). Unset: the 6-DOF proxy's torque spring is the linear spring times the tool's
  /// extent squared (angular_stiffness_for), which makes the torque felt the constraints' r x F;
  /// the penalty path's coupling (step()) turns with the hand.
  std::optional<double> angular_stiffness{};
  double angular_damping = 0.0;          ///< B_r [N m s/rad]
  /// b_r, the device's rotational damping [N m s/rad], which the rotational bound relies on. The
  /// default, 1e-3 (2 N m/rad at 1 kHz), is assumed as device_damping's 1 N s/m is: the linear
  /// damping at a 3 cm lever; give the device's measured one.
  double device_angular_damping = 1.0e-3;
  double period_s = 0.001;               ///< haptic period T [s] (1 / rate)
  double passivity_margin = 0.9;         ///< fraction of the bound actually used, in (0, 1]
  double proxy_mass_kg = 0.1;            ///< mass of the simulated tool [kg], > 0
  double proxy_inertia_kg_m2 = 1.0e-4;   ///< scalar rotational inertia of the tool [kg m^2], > 0
};

/// What one coupling step produced. Trivially copyable.
struct CouplingOutput {
  Wrench device_wrench{};   ///< to send to the device [N, N m], world frame (torque about the handle)
  Pose world_from_proxy{};  ///< the simulated tool's pose after the step
  BodyMotion proxy{};       ///< its centre and velocities after the step (world frame)
};

/// A simulated tool (proxy) coupled to the device handle by a spring-damper. The collision and
/// penalty forces act on the proxy; the device feels only the coupling force, whose stiffness is
/// bounded so that the loop stays passive even when the volumetric penalty stiffens with depth
/// (K_eff = eps_c * sum pi a_ij^2 grows without bound).
///
/// The proxy is integrated with semi-implicit Euler (velocity first). Owned by one thread (the
/// haptic thread); step() is real-time safe.
class VirtualCoupling {
 public:
  /// Clamps the requested stiffnesses to passivity_margin * max_passive_stiffness(...).
  explicit VirtualCoupling(const VirtualCouplingOptions& options = {});

  /// Places the proxy at the handle pose with zero velocity (call before the first step).
  void reset(const Pose& world_from_device);

  /// Advances the proxy by dt [s]: the coupling pulls it towards the handle, `contact_on_proxy`
  /// (world frame, torque about the proxy's origin) pushes it. Returns the reaction the device
  /// must render. Velocities are world frame [m/s], [rad/s].
  CouplingOutput step(const Pose& world_from_device, const Vec3& device_velocity, const Vec3& device_angular_velocity,
                      const Wrench& contact_on_proxy, double dt);

  /// The stiffnesses in use after clamping (step()'s: an unset angular_stiffness is 0 here).
  double stiffness() const { return stiffness_; }
  double angular_stiffness() const { return angular_stiffness_; }
  /// The largest torque spring the rotational bound allows [N m/rad]: margin * 2 (b_r - |B_r|) / T.
  double angular_stiffness_bound() const { return angular_bound_; }
  /// The torque spring [N m/rad] that goes with a linear spring `linear_n_m` [N/m] on a tool of
  /// extent `extent_m` [m]: the requested angular_stiffness, or unset linear * extent^2, clamped to
  /// the rotational bound. With the proxy's solver weighing rotation by the same extent (a step
  /// minimises |t - t*|^2 + R^2 |w - w*|^2), the spring wrench (K dt, K R^2 dw) of a proxy held by
  /// one contact is that contact's force and its moment r x F. Real-time safe.
  double angular_stiffness_for(double linear_n_m, double extent_m) const;
  /// True when a requested stiffness exceeded the passive bound and was lowered.
  bool stiffness_limited() const { return stiffness_limited_; }
  const VirtualCouplingOptions& options() const { return options_; }
  const Pose& world_from_proxy() const { return proxy_pose_; }

 private:
  VirtualCouplingOptions options_{};
  double stiffness_ = 0.0;
  double angular_stiffness_ = 0.0;
  double angular_bound_ = 0.0;
  bool stiffness_limited_ = false;
  Pose proxy_pose_{};
  Vec3 proxy_velocity_{};
  Vec3 proxy_angular_velocity_{};
};

/// Rotation vector (axis * angle, angle in [0, pi]) of the unit quaternion q. Real-time safe.
Vec3 rotation_vector(const Quat& q);

}  // namespace uh::forcecomp
