#pragma once
/// \file
/// TraceSample: one haptic tick as recorded for later analysis (state in, force out).

#include <cstdint>
#include <ostream>
#include <type_traits>

#include "uh/haptico/device_command.hpp"
#include "uh/haptico/device_state.hpp"

namespace uh::haptico {

/// Bits of TraceSample::flags: what the safety stage did in that tick.
enum TraceFlag : std::uint32_t {
  kTraceForceClamped = 1u << 0,   ///< |force| was above the smallest limit and was scaled down
  kTraceTorqueClamped = 1u << 1,  ///< |torque| was above the smallest limit and was scaled down
  kTraceNonFinite = 1u << 2,      ///< the requested command had a NaN/inf and was replaced by zero
  kTraceZeroed = 1u << 3,         ///< zero was sent because of halt() or a latched device fault
  kTraceDeviceError = 1u << 4,    ///< read_state() reported an error this tick
  kTraceFading = 1u << 5,         ///< the soft-start fade scaled the command down
  kTraceDeviceLimit = 1u << 6,    ///< the device's limit (DeviceInfo) clamped the force or torque
  kTraceToolLimit = 1u << 7,      ///< the tool's limit clamped the force or torque
  kTraceSafetyLimit = 1u << 8,    ///< the session's safety limit clamped the force or torque
  kTraceRateLimit = 1u << 9,      ///< the change from the previous tick was bounded by the rate limit
  kTraceStopped = 1u << 10,       ///< not a tick: the zero command sent when the haptic loop ended
};

/// One tick: when, what the device reported, what the delegates asked for and what was sent.
/// Trivially copyable, so that the haptic thread can hand it over through an SpscQueue.
struct TraceSample {
  double tick_time_s = 0.0;     ///< the tick's time [s] (see HapticManager::tick_time_s)
  DeviceState state{};          ///< as read at the start of the tick
  DeviceCommand requested{};    ///< sum of what the ForceOnHapticTick delegates wrote
  DeviceCommand sent{};         ///< after the safety stage: what the device got
  std::uint32_t flags = 0;      ///< TraceFlag bits
};
static_assert(std::is_trivially_copyable_v<TraceSample>);

/// Writes the CSV header matching write_trace_row(). Not real-time safe.
void write_trace_header(std::ostream& out);
/// Writes one CSV row: tick_time_s, device time, position, orientation (w,x,y,z), linear and
/// angular velocity, buttons, status, requested force/torque, sent force/torque, flags.
/// Not real-time safe.
void write_trace_row(std::ostream& out, const TraceSample& sample);

}  // namespace uh::haptico
