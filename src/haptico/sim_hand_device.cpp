#include "uh/haptico/sim_hand_device.hpp"

#include <algorithm>

namespace uh::haptico {

SimHandDevice::SimHandDevice(const SimHandOptions& options)
    : SimulatedDevice("sim-hand", options.device), options_(options), position_(options.target_start) {}

Vec3 SimHandDevice::target_at(double t) const {
  const double u = std::clamp(t / options_.duration_s, 0.0, 1.0);
  return options_.target_start + u * (options_.target_end - options_.target_start);
}

DeviceState SimHandDevice::sample(double) const {
  DeviceState s;
  s.position = position_;
  s.linear_velocity = velocity_;
  return s;
}

void SimHandDevice::integrate(double t, double dt, const DeviceCommand& cmd) {
  const Vec3 target = target_at(t);
  const Vec3 target_velocity =
      t < options_.duration_s ? (options_.target_end - options_.target_start) / options_.duration_s : Vec3{};
  const Vec3 f = options_.hand_stiffness * (target - position_) + options_.hand_damping * (target_velocity - velocity_) -
                 options_.device_damping * velocity_ + cmd.force;
  velocity_ += (dt / options_.handle_mass_kg) * f;
  position_ += dt * velocity_;
}

}  // namespace uh::haptico
