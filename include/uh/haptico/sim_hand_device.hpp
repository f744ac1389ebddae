#pragma once
/// \file
/// SimHandDevice ("sim-hand"): a user's hand pulling the handle, so the force acts back on the motion.

#include "uh/haptico/simulated_device.hpp"

namespace uh::haptico {

/// Options of a SimHandDevice. Config keys: handle_mass_kg, hand_stiffness, hand_damping,
/// device_damping, target_start, target_end, duration_s, bounce, substeps, plus the
/// SimDeviceOptions keys.
struct SimHandOptions {
  SimDeviceOptions device{};
  double handle_mass_kg = 0.1;     ///< moving mass of handle plus hand [kg], > 0
  double hand_stiffness = 300.0;   ///< spring from the hand target to the handle [N/m], >= 0
  double hand_damping = 3.0;       ///< damper on the velocity relative to the target [N s/m], >= 0
  double device_damping = 0.5;     ///< the device's own friction-like damping [N s/m], >= 0
  Vec3 target_start{};             ///< where the hand starts (and the handle) [m]
  Vec3 target_end{0.0, 0.0, -0.03};  ///< where the hand moves to [m]
  double duration_s = 1.0;         ///< time the target takes from start to end [s], > 0
  /// false: the target stays at the end; true: it goes back and forth, a closed path every
  /// 2 duration_s (start, end, start), for measuring the energy exchanged over whole cycles
  bool bounce = false;
  int substeps = 10;               ///< integration steps per period (the command is held over all of them), >= 1
};

/// A mass-spring-damper "hand": the handle of mass m is pulled by a spring-damper towards a target
/// moving at constant speed from target_start to target_end (and back, with bounce), damped by the
/// device, and pushed by the commanded force:
///     m dv/dt = k (x_t - x) + c (v_t - v) - b v + F_cmd
/// integrated with semi-implicit Euler in `substeps` steps per period while the command is held
/// (as a real servo loop holds it between samples). With a wall the handle settles where the
/// hand spring balances the wall force, so the loop's stability can be observed. Orientation stays
/// identity (the torque is recorded, not simulated).
class SimHandDevice final : public SimulatedDevice {
 public:
  explicit SimHandDevice(const SimHandOptions& options);
  const SimHandOptions& options() const { return options_; }
  /// Where the hand target is at time t [m].
  Vec3 target_at(double t) const;
  /// The hand target's velocity at time t [m/s].
  Vec3 target_velocity_at(double t) const;

 private:
  DeviceState sample(double t) const override;
  void integrate(double t, double dt, const DeviceCommand& cmd) override;
  SimHandOptions options_;
  Vec3 position_{};
  Vec3 velocity_{};
};

}  // namespace uh::haptico
