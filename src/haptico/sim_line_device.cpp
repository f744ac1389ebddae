#include "uh/haptico/sim_line_device.hpp"

#include <cmath>

namespace uh::haptico {

SimLineDevice::SimLineDevice(const SimLineOptions& options) : ScriptedDevice("sim-line", options.device), options_(options) {}

Pose SimLineDevice::pose_at(double t) const {
  const double u = t / options_.duration_s;
  double s = 0.0;
  if (options_.bounce) {
    const double phase = std::fmod(u, 2.0);
    s = phase <= 1.0 ? phase : 2.0 - phase;
  } else {
    s = u < 1.0 ? u : 1.0;
  }
  return Pose{Quat{}, options_.start + s * (options_.end - options_.start)};
}

}  // namespace uh::haptico
