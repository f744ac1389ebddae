#pragma once
/// \file
/// DeviceState: one timestamped snapshot of a device, read once per haptic tick.

#include <cstdint>
#include <type_traits>

#include "uh/core/math.hpp"

namespace uh::haptico {

/// Whether a read produced a valid state.
enum class DeviceStatus : std::uint8_t {
  kOk,       ///< the state is valid
  kNotOpen,  ///< the device is not open; the state is meaningless
  kFault,    ///< the device reported an error (lost connection, amplifier fault); meaningless
};

/// Everything the haptic tick knows about the handle at one instant. All fields share `time_s`
/// (no per-field getters with different sampling times). Frame: the device's base frame.
/// Trivially copyable.
struct DeviceState {
  /// When the sample was taken [s] (device clock; simulated devices: simulated time). Must
  /// increase from one tick to the next while the device is live: HapticManager treats a time
  /// that stops advancing (HapticManagerOptions::max_frozen_ticks) as a stalled device.
  double time_s = 0.0;
  Vec3 position{};                  ///< handle position [m]
  Quat orientation{};               ///< handle orientation (unit quaternion)
  Vec3 linear_velocity{};           ///< [m/s]
  Vec3 angular_velocity{};          ///< [rad/s]
  std::uint32_t buttons = 0;        ///< bit i set while button i is pressed
  DeviceStatus status = DeviceStatus::kNotOpen;
};
static_assert(std::is_trivially_copyable_v<DeviceState>);

}  // namespace uh::haptico
