#pragma once
/// \file
/// SimLineDevice ("sim-line"): the handle moves along a straight segment.

#include "uh/haptico/simulated_device.hpp"

namespace uh::haptico {

/// Options of a SimLineDevice. Config keys: start, end ("x,y,z" [m]), duration_s, bounce (0/1),
/// plus the SimDeviceOptions keys rate_hz, max_force_n, max_torque_nm, dof_actuated, workspace.
struct SimLineOptions {
  SimDeviceOptions device{};
  Vec3 start{};                 ///< [m]
  Vec3 end{0.0, 0.0, -0.02};    ///< [m]
  double duration_s = 1.0;      ///< time from start to end [s], > 0
  bool bounce = true;           ///< go back and forth; otherwise stay at the end
};

/// Moves from start to end at constant speed, then back (bounce) or stays at the end.
class SimLineDevice final : public ScriptedDevice {
 public:
  explicit SimLineDevice(const SimLineOptions& options);
  const SimLineOptions& options() const { return options_; }

 private:
  Pose pose_at(double t) const override;
  SimLineOptions options_;
};

}  // namespace uh::haptico
