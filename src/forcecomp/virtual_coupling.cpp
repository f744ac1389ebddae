#include "uh/forcecomp/virtual_coupling.hpp"

#include <algorithm>
#include <cmath>

namespace uh::forcecomp {

double max_passive_stiffness(double device_damping, double period_s, double coupling_damping) {
  if (!std::isfinite(device_damping) || !std::isfinite(period_s) || !std::isfinite(coupling_damping)) return 0.0;
  if (!(period_s > 0.0)) return 0.0;
  const double margin = device_damping - std::abs(coupling_damping);
  return margin > 0.0 ? 2.0 * margin / period_s : 0.0;
}

Vec3 rotation_vector(const Quat& q_in) {
  Quat q = normalized(q_in);
  if (q.w < 0.0) q = {-q.w, -q.x, -q.y, -q.z};  // shortest way round
  const Vec3 v{q.x, q.y, q.z};
  const double s = norm(v);
  if (s < 1e-12) return 2.0 * v;  // small angle: angle ~ 2 s
  const double angle = 2.0 * std::atan2(s, q.w);
  return v * (angle / s);
}

VirtualCoupling::VirtualCoupling(const VirtualCouplingOptions& options) : options_(options) {
  const double margin = std::clamp(options.passivity_margin, 0.0, 1.0);
  const double k_max = margin * max_passive_stiffness(options.device_damping, options.period_s, options.damping);
  angular_bound_ =
      margin * max_passive_stiffness(options.device_angular_damping, options.period_s, options.angular_damping);
  const double angular = options.angular_stiffness.value_or(0.0);
  stiffness_ = std::clamp(options.stiffness, 0.0, k_max);
  angular_stiffness_ = std::clamp(angular, 0.0, angular_bound_);
  stiffness_limited_ = options.stiffness > k_max || angular > angular_bound_;
}

double VirtualCoupling::angular_stiffness_for(double linear_n_m, double extent_m) const {
  const double wanted = options_.angular_stiffness.value_or(linear_n_m * extent_m * extent_m);
  return std::isfinite(wanted) ? std::clamp(wanted, 0.0, angular_bound_) : 0.0;
}

void VirtualCoupling::reset(const Pose& world_from_device) {
  proxy_pose_ = world_from_device;
  proxy_velocity_ = {};
  proxy_angular_velocity_ = {};
}

CouplingOutput VirtualCoupling::step(const Pose& world_from_device, const Vec3& device_velocity,
                                     const Vec3& device_angular_velocity, const Wrench& contact_on_proxy, double dt) {
  // coupling force on the proxy; the device feels the opposite
  const Vec3 f_coupling = stiffness_ * (world_from_device.position - proxy_pose_.position) +
                          options_.damping * (device_velocity - proxy_velocity_);
  Vec3 t_coupling{};
  if (angular_stiffness_ > 0.0 || options_.angular_damping > 0.0) {
    const Quat error = world_from_device.rotation * conjugate(proxy_pose_.rotation);
    t_coupling = angular_stiffness_ * rotation_vector(error) +
                 options_.angular_damping * (device_angular_velocity - proxy_angular_velocity_);
  }

  CouplingOutput out;
  out.device_wrench.force = -f_coupling;
  out.device_wrench.torque = -t_coupling;

  // semi-implicit Euler: velocity from the forces, then position from the new velocity
  const double m = options_.proxy_mass_kg > 0.0 ? options_.proxy_mass_kg : 1.0;
  const double inertia = options_.proxy_inertia_kg_m2 > 0.0 ? options_.proxy_inertia_kg_m2 : 1.0;
  proxy_velocity_ += (dt / m) * (f_coupling + contact_on_proxy.force);
  proxy_pose_.position += dt * proxy_velocity_;
  if (angular_stiffness_ > 0.0 || options_.angular_damping > 0.0) {
    proxy_angular_velocity_ += (dt / inertia) * (t_coupling + contact_on_proxy.torque);
    const Vec3& w = proxy_angular_velocity_;
    const Quat wq{0.0, w.x, w.y, w.z};
    const Quat dq = wq * proxy_pose_.rotation;
    const Quat& q = proxy_pose_.rotation;
    proxy_pose_.rotation =
        normalized(Quat{q.w + 0.5 * dt * dq.w, q.x + 0.5 * dt * dq.x, q.y + 0.5 * dt * dq.y, q.z + 0.5 * dt * dq.z});
  } else {
    // 3-DOF: the tool turns with the hand
    proxy_pose_.rotation = world_from_device.rotation;
    proxy_angular_velocity_ = device_angular_velocity;
  }
  out.world_from_proxy = proxy_pose_;
  out.proxy.center_of_mass_world = proxy_pose_.position;
  out.proxy.linear_velocity_world = proxy_velocity_;
  out.proxy.angular_velocity_world = proxy_angular_velocity_;
  return out;
}

}  // namespace uh::forcecomp
