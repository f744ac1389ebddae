#include "uh/haptico/simulated_device.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace uh::haptico {

namespace {

// motors saturate: keep the direction, cap the magnitude
Vec3 saturate(Vec3 v, double limit) {
  clamp_norm(v, limit);
  return v;
}

}  // namespace

SimulatedDevice::SimulatedDevice(std::string name, const SimDeviceOptions& options) {
  info_.name = std::move(name);
  info_.dof_sensed = 6;
  info_.dof_actuated = options.dof_actuated;
  info_.max_force_n = options.max_force_n;
  info_.max_torque_nm = options.dof_actuated == 6 ? options.max_torque_nm : 0.0;
  info_.workspace_half_extents = options.workspace_half_extents;
  info_.nominal_rate_hz = options.rate_hz;
  period_s_ = 1.0 / options.rate_hz;
}

Status SimulatedDevice::open() {
  open_ = true;
  return Ok{};
}

Status SimulatedDevice::close() {
  last_command_ = {};
  open_ = false;
  return Ok{};
}

DeviceState SimulatedDevice::read_state() {
  if (!open_) return DeviceState{.time_s = time_s_, .status = DeviceStatus::kNotOpen};
  DeviceState s = sample(time_s_);
  s.time_s = time_s_;
  s.status = DeviceStatus::kOk;
  return s;
}

void SimulatedDevice::command(const DeviceCommand& cmd) {
  if (!open_) return;
  last_command_.force = saturate(cmd.force, info_.max_force_n);
  last_command_.torque = info_.dof_actuated == 6 ? saturate(cmd.torque, info_.max_torque_nm) : Vec3{};
  ++commands_;
  advance(period_s_);
}

void SimulatedDevice::advance(double dt) {
  if (!(dt > 0.0)) return;
  integrate(time_s_, dt, last_command_);
  time_s_ += dt;
}

DeviceState ScriptedDevice::sample(double t) const {
  const Pose p = pose_at(t);
  // central difference; the step is small against any scripted motion and exact for lines
  const double h = 1e-4;
  const Pose before = pose_at(std::max(0.0, t - h));
  const Pose after = pose_at(t + h);
  const double span = (t + h) - std::max(0.0, t - h);
  DeviceState s;
  s.position = p.position;
  s.orientation = p.rotation;
  s.linear_velocity = (after.position - before.position) / span;
  // q_after = exp(w span / 2) q_before: w from the vector part of q_after * conj(q_before)
  Quat dq = after.rotation * conjugate(before.rotation);
  if (dq.w < 0.0) dq = {-dq.w, -dq.x, -dq.y, -dq.z};
  s.angular_velocity = Vec3{dq.x, dq.y, dq.z} * (2.0 / span);
  s.buttons = buttons_at(t);
  return s;
}

}  // namespace uh::haptico
