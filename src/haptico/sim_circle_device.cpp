#include "uh/haptico/sim_circle_device.hpp"

#include <cmath>

namespace uh::haptico {

SimCircleDevice::SimCircleDevice(const SimCircleOptions& options)
    : ScriptedDevice("sim-circle", options.device), options_(options) {
  const Vec3 n = normalized(options.axis);
  // any vector not parallel to n gives a perpendicular basis
  const Vec3 helper = std::abs(n.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  e1_ = normalized(cross(helper, n));
  e2_ = cross(n, e1_);
}

Pose SimCircleDevice::pose_at(double t) const {
  const double angle = 2.0 * kPi * t / options_.period_s;
  return Pose{Quat{}, options_.center + options_.radius * (std::cos(angle) * e1_ + std::sin(angle) * e2_)};
}

}  // namespace uh::haptico
