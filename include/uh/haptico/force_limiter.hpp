#pragma once
/// \file
/// ForceLimiter: the one limit chain between what the delegates ask for and what a device gets.

#include <cstdint>
#include <limits>

#include "uh/core/math.hpp"
#include "uh/haptico/device_command.hpp"
#include "uh/haptico/device_info.hpp"

namespace uh::haptico {

/// "No limit" for a WrenchLimit field.
inline constexpr double kNoLimit = std::numeric_limits<double>::infinity();

/// Magnitude limits of a force and a torque (aggregate). kNoLimit: this source sets none.
struct WrenchLimit {
  double max_force_n = kNoLimit;    ///< |force| limit [N], > 0
  double max_torque_nm = kNoLimit;  ///< |torque| limit [N m], > 0
};

/// Largest change of the command from one tick to the next, as a rate (aggregate). Zero is sent
/// at once whatever this says: stopping is never rate-limited.
struct ForceRateLimit {
  /// [N/s], > 0; kNoLimit turns it off. The default lets a full 8 N device limit build up in
  /// 8 ms (1 N per tick at 1 kHz): above what a stiff virtual wall asks of a moving hand
  /// (2 N/mm at 0.5 m/s), well below a step from a late collision frame.
  double max_force_n_per_s = 1000.0;
  /// [N m/s], > 0; kNoLimit turns it off (0.05 N m per tick at 1 kHz).
  double max_torque_nm_per_s = 50.0;
};

/// The limits of a session besides the device's own (options aggregate): the tool's (scene
/// `tool.force.max_*`), the session's safety limits (scene `force.safety.max_*`) and the rate limit.
struct ForceLimitOptions {
  WrenchLimit tool{};
  WrenchLimit safety{};
  ForceRateLimit rate{};
};

/// What limited one tick: TraceFlag bits (see trace_sample.hpp) of the limits that engaged.
using LimitFlags = std::uint32_t;

/// The limit chain: force and torque are clamped to the smallest of the device's limits
/// (DeviceInfo), the tool's and the session's safety limits, keeping their direction; then a fade
/// gain in [0, 1] scales them; then the change from the previous command is bounded by the rate
/// limit (per tick: rate / tick rate), all with uh::clamp_norm. Each magnitude clamp is credited to the
/// source whose limit was the smallest (ties: device, then tool, then safety); the rate limit to itself.
///
/// Zero bypasses the chain: zero() is what a halt, a fault, a NaN or a stop sends, at once, and
/// the next apply() ramps up from it. The output of apply() stays within the smallest magnitude
/// limit: it lies between the previous output and the clamped target, both within it.
///
/// Threads: one thread (the haptic thread); apply() and zero() are real-time safe.
class ForceLimiter {
 public:
  ForceLimiter() = default;
  /// The chain for `device` (its max_force_n / max_torque_nm; torque limit 0 for devices without
  /// torque) at `tick_rate_hz` [Hz], > 0.
  ForceLimiter(const DeviceInfo& device, const ForceLimitOptions& options, double tick_rate_hz);

  /// Returns the command to send for `wanted` (finite) faded by `gain` in [0, 1]; adds the
  /// TraceFlag bits of what engaged to `flags`.
  DeviceCommand apply(const DeviceCommand& wanted, double gain, LimitFlags& flags);
  /// Records that zero was sent: the next apply() changes the command from zero.
  void zero() { last_ = DeviceCommand{}; }

  /// The smallest force / torque limit of the three sources [N], [N m].
  double max_force_n() const { return force_.limit; }
  double max_torque_nm() const { return torque_.limit; }
  /// The rate limit per tick [N], [N m] (kNoLimit when off).
  double max_force_step_n() const { return max_force_step_n_; }
  double max_torque_step_nm() const { return max_torque_step_nm_; }

 private:
  struct Smallest {
    double limit = kNoLimit;
    LimitFlags flag = 0;  // the TraceFlag of the source that sets it
  };
  static Smallest smallest(double device, double tool, double safety);

  Smallest force_{};
  Smallest torque_{};
  double max_force_step_n_ = kNoLimit;
  double max_torque_step_nm_ = kNoLimit;
  DeviceCommand last_{};
};

}  // namespace uh::haptico
