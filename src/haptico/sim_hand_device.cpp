#include "uh/haptico/sim_hand_device.hpp"

#include <algorithm>
#include <cmath>

namespace uh::haptico {

SimHandDevice::SimHandDevice(const SimHandOptions& options)
    : SimulatedDevice("sim-hand", options.device), options_(options), position_(options.target_start) {}

namespace {

// where along start -> end the target is at time t, in [0, 1], and d/dt of that [1/s]
struct PathPoint {
  double u = 0.0;
  double du_dt = 0.0;
};

PathPoint path_point(double t, double duration_s, bool bounce) {
  const double s = std::max(0.0, t) / duration_s;
  if (!bounce) return s < 1.0 ? PathPoint{s, 1.0 / duration_s} : PathPoint{1.0, 0.0};
  // a triangle wave: out over [0, 1), back over [1, 2)
  const double phase = std::fmod(s, 2.0);
  return phase < 1.0 ? PathPoint{phase, 1.0 / duration_s} : PathPoint{2.0 - phase, -1.0 / duration_s};
}

}  // namespace

Vec3 SimHandDevice::target_at(double t) const {
  const double u = path_point(t, options_.duration_s, options_.bounce).u;
  return options_.target_start + u * (options_.target_end - options_.target_start);
}

Vec3 SimHandDevice::target_velocity_at(double t) const {
  const double du_dt = path_point(t, options_.duration_s, options_.bounce).du_dt;
  return du_dt * (options_.target_end - options_.target_start);
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
  for (int i = 0; i < substeps; ++i) {
    const double ti = t + i * h;
    const Vec3 f = options_.hand_stiffness * (target_at(ti) - position_) +
                   options_.hand_damping * (target_velocity_at(ti) - velocity_) - options_.device_damping * velocity_ +
                   cmd.force;
    velocity_ += (h / options_.handle_mass_kg) * f;
    position_ += h * velocity_;
  }
}

}  // namespace uh::haptico
