#pragma once
/// \file
/// DeviceInfo: what a haptic device is and what it can do (after CHAI3D's device-info struct).

#include <string>

#include "uh/core/math.hpp"

namespace uh::haptico {

/// Static description of a device, valid after a successful open(). Units are SI; positions are
/// in the device's base frame (the frame of DeviceState).
struct DeviceInfo {
  std::string name;               ///< driver name and model, e.g. "sim-line"
  int dof_sensed = 0;             ///< 3 (position) or 6 (position and orientation)
  int dof_actuated = 0;           ///< 3 (force) or 6 (force and torque); 0 for a passive input device
  double max_force_n = 0.0;       ///< largest force the device may be commanded [N], > 0 if actuated
  double max_torque_nm = 0.0;     ///< largest torque [N m], > 0 if dof_actuated == 6
  Vec3 workspace_half_extents{};  ///< half extents of the reachable box about the base origin [m]
  double nominal_rate_hz = 1000.0;  ///< servo rate the device is made for [Hz]
  std::string model{};   ///< the model as the device reports it ("" for simulated devices), e.g. "omega.3"
  std::string serial{};  ///< its serial number as text ("" when it has none)
};

}  // namespace uh::haptico
