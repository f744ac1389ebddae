#pragma once
/// \file
/// SimulatedDevice: base of the devices that need no hardware (sim-line, sim-circle, sim-raster,
/// sim-replay, sim-hand).

#include <cstdint>

#include "uh/haptico/haptic_device.hpp"

namespace uh::haptico {

/// Settings shared by all simulated devices (options aggregate).
struct SimDeviceOptions {
  double rate_hz = 1000.0;          ///< simulated servo rate [Hz]; each command() advances time by 1 / rate_hz
  double max_force_n = 8.0;         ///< force limit the device reports and saturates at [N]
  double max_torque_nm = 0.5;       ///< torque limit [N m]
  int dof_actuated = 3;             ///< 3 or 6
  Vec3 workspace_half_extents{0.1, 0.1, 0.1};  ///< [m]
};

/// A device that lives in simulated time. Deterministic: the time starts at 0 and advances by
/// exactly 1 / rate_hz on every command() (one haptic tick = read_state() then command()), or by
/// an explicit advance(dt), independent of the wall clock, so stepped tests need no threads.
///
/// Threads: like any HapticDevice. The test accessors (time_s, last_command, commands) belong to
/// the thread that ticks the device.
class SimulatedDevice : public HapticDevice {
 public:
  DeviceInfo info() const override { return info_; }
  Status open() override;
  Status close() override;
  /// The state at the current simulated time (kNotOpen before open()).
  DeviceState read_state() override;
  /// Records `cmd` (saturated at the limits, like motors), lets the model react to it for one
  /// period and advances the time by 1 / rate_hz. Ignored before open().
  void command(const DeviceCommand& cmd) override;
  /// Simulated devices do not fault: always "".
  std::string fault_reason() override { return {}; }

  /// Advances the simulated time by `dt` [s] under the last command. Real-time safe.
  void advance(double dt);
  double time_s() const { return time_s_; }
  bool is_open() const { return open_; }
  /// The last command as rendered (after saturation).
  const DeviceCommand& last_command() const { return last_command_; }
  std::uint64_t commands() const { return commands_; }
  double period_s() const { return period_s_; }

 protected:
  SimulatedDevice(std::string name, const SimDeviceOptions& options);
  /// The state at simulated time t (status is filled in by the base).
  virtual DeviceState sample(double t) const = 0;
  /// Integrates the model from time t over dt under `cmd`; scripted devices ignore the force.
  virtual void integrate(double t, double dt, const DeviceCommand& cmd) = 0;

 private:
  DeviceInfo info_{};
  double period_s_ = 0.001;
  double time_s_ = 0.0;
  bool open_ = false;
  DeviceCommand last_command_{};
  std::uint64_t commands_ = 0;
};

/// A simulated device moving along a path given as a function of time; the commanded force does not
/// change the motion (the "hand" is infinitely stiff). Velocities are central differences of the path.
class ScriptedDevice : public SimulatedDevice {
 protected:
  using SimulatedDevice::SimulatedDevice;
  /// The handle pose at time t [s].
  virtual Pose pose_at(double t) const = 0;
  /// The buttons held at time t (bit i: button i); scripts without buttons hold none.
  virtual std::uint32_t buttons_at(double) const { return 0; }
  DeviceState sample(double t) const override;
  void integrate(double, double, const DeviceCommand&) override {}
};

}  // namespace uh::haptico
