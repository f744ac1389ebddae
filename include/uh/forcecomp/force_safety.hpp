#pragma once
/// \file
/// ForceSafety: the NaN guard, the contact watchdog and the stop of a force controller's wrench.

#include <atomic>
#include <cstdint>

#include "uh/forcecomp/contact_watchdog.hpp"
#include "uh/forcecomp/wrench.hpp"

namespace uh::forcecomp {

/// Options of a ForceSafety stage (options aggregate).
struct ForceSafetyOptions {
  ContactWatchdogOptions watchdog{};
};

/// Counters of a ForceSafety stage; a snapshot, trivially copyable.
struct ForceSafetyCounters {
  std::uint64_t ticks = 0;         ///< calls to apply()
  std::uint64_t nonfinite = 0;     ///< ticks with a NaN/inf component (replaced by zero)
  std::uint64_t stale_ticks = 0;   ///< ticks with stale contact data (watchdog ramping down / held at 0)
  std::uint64_t zeroed_ticks = 0;  ///< ticks zeroed because of stop() or a device fault
};

/// Makes a computed wrench fit to send: replaces any non-finite wrench by zero, fades it out with
/// a ContactWatchdog when the contact data is old, and outputs zero while stopped or faulted.
///
/// Order: non-finite guard, watchdog gain, stop/fault. Force and torque limits are not applied
/// here: the device's, the tool's and the session's limits and the rate limit form one chain at
/// the end of the haptic tick (haptico::ForceLimiter, applied by HapticManager to the summed
/// command of all delegates).
///
/// Threads: apply() belongs to one thread (the haptic thread) and is real-time safe (no allocation,
/// lock, throw or log: it counts). stop(), resume(), report_fault() and counters() may be called
/// from any thread (atomics).
class ForceSafety {
 public:
  ForceSafety() = default;
  explicit ForceSafety(const ForceSafetyOptions& options) : options_(options), watchdog_(options.watchdog) {}

  /// Returns the wrench to send at time `now_s` [s] given the raw wrench and the time the contact
  /// data behind it was computed (`data_time_s`, [s], same clock).
  Wrench apply(const Wrench& raw, double now_s, double data_time_s);

  /// Outputs zero from the next apply() on, until resume().
  void stop() { stopped_.store(true, std::memory_order_release); }
  /// Ends a stop and clears a fault; the watchdog restarts at gain 0 and ramps up (no step).
  void resume();
  /// Records a device error: outputs zero until resume().
  void report_fault() { faulted_.store(true, std::memory_order_release); }

  bool stopped() const { return stopped_.load(std::memory_order_acquire); }
  bool faulted() const { return faulted_.load(std::memory_order_acquire); }
  ForceSafetyCounters counters() const;
  const ForceSafetyOptions& options() const { return options_; }
  /// The watchdog's current gain in [0, 1] (haptic thread only).
  double watchdog_gain() const { return watchdog_.gain(); }

 private:
  ForceSafetyOptions options_{};
  ContactWatchdog watchdog_{};
  std::atomic<bool> stopped_{false};
  std::atomic<bool> faulted_{false};
  std::atomic<bool> resume_requested_{false};
  std::atomic<std::uint64_t> ticks_{0};
  std::atomic<std::uint64_t> nonfinite_{0};
  std::atomic<std::uint64_t> stale_ticks_{0};
  std::atomic<std::uint64_t> zeroed_ticks_{0};
};

}  // namespace uh::forcecomp
