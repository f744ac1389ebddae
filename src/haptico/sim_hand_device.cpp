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
  // the hand and the handle move continuously while the command is held for the whole period
  // (zero-order hold): substeps resolve that, which is where sampled walls gain energy
  const int substeps = std::max(1, options_.substeps);
  const double h = dt / substeps;
  const Vec3 travel_velocity = (options_.target_end - options_.target_start) / options_.duration_s;
  for (int i = 0; i < substeps; ++i) {
    const double ti = t + i * h;
    const Vec3 target_velocity = ti < options_.duration_s ? travel_velocity : Vec3{};
    const Vec3 f = options_.hand_stiffness * (target_at(ti) - position_) +
                   options_.hand_damping * (target_velocity - velocity_) - options_.device_damping * velocity_ +
                   cmd.force;
    velocity_ += (h / options_.handle_mass_kg) * f;
    position_ += h * velocity_;
  }
}

}  // namespace uh::haptico
