#pragma once
/// \file
/// DeviceCommand: the force and torque sent to a device in one haptic tick.

#include <type_traits>

#include "uh/core/math.hpp"

namespace uh::haptico {

/// What the handle should render until the next tick. Frame: the device's base frame (the frame of
/// DeviceState), torque about the handle point. Trivially copyable; the zero value is "no force".
struct DeviceCommand {
  Vec3 force{};   ///< [N]
  Vec3 torque{};  ///< [N m]; ignored by devices with dof_actuated < 6
};
static_assert(std::is_trivially_copyable_v<DeviceCommand>);

}  // namespace uh::haptico
