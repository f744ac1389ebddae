#pragma once
/// \file
/// SimCircleDevice ("sim-circle"): the handle runs round a circle.

#include "uh/haptico/simulated_device.hpp"

namespace uh::haptico {

/// Options of a SimCircleDevice. Config keys: center, axis ("x,y,z"), radius, period_s, plus the
/// SimDeviceOptions keys.
struct SimCircleOptions {
  SimDeviceOptions device{};
  Vec3 center{};               ///< [m]
  Vec3 axis{0.0, 0.0, 1.0};    ///< circle normal (need not be unit); the motion is right-handed about it
  double radius = 0.02;        ///< [m], > 0
  double period_s = 2.0;       ///< time for one turn [s], > 0
};

/// Runs round the circle at constant speed, starting at center + radius * e1 (e1 a fixed unit
/// vector perpendicular to the axis); orientation stays identity.
class SimCircleDevice final : public ScriptedDevice {
 public:
  explicit SimCircleDevice(const SimCircleOptions& options);
  const SimCircleOptions& options() const { return options_; }

 private:
  Pose pose_at(double t) const override;
  SimCircleOptions options_;
  Vec3 e1_{};
  Vec3 e2_{};
};

}  // namespace uh::haptico
