#pragma once
/// \file
/// ContactWatchdog: fades the force out when collision data gets old.

namespace uh::forcecomp {

/// Options of a ContactWatchdog (options aggregate).
struct ContactWatchdogOptions {
  double max_age_s = 0.02;  ///< contact data older than this [s] counts as stale (collision thread stalled)
  double ramp_s = 0.05;     ///< time [s] for the gain to go from 1 to 0 (and back), > 0
};

/// A gain in [0, 1] that ramps down to zero at a bounded rate while the contact data is older than
/// max_age_s, and ramps back up at the same rate once fresh data arrives (never a step).
///
/// Why a ramp and not a cut: cutting a large force in one tick is itself a jolt on the user's hand.
/// Owned and called by one thread (the haptic thread); update() is real-time safe.
class ContactWatchdog {
 public:
  ContactWatchdog() = default;
  explicit ContactWatchdog(const ContactWatchdogOptions& options) : options_(options) {}

  /// Advances the gain to time `now_s` [s] given the time `data_time_s` [s] at which the contact
  /// data in use was computed; returns the new gain. A non-finite time counts as stale. The first
  /// call starts at gain 1 if the data is fresh.
  double update(double now_s, double data_time_s);

  double gain() const { return gain_; }
  /// True while the data in use is stale.
  bool stale() const { return stale_; }
  /// Sets the gain (clamped to [0, 1]) and forgets the last time: reset() after a deliberate
  /// pause, reset(0.0) to make the force fade in after a stop.
  void reset(double gain = 1.0);
  const ContactWatchdogOptions& options() const { return options_; }

 private:
  ContactWatchdogOptions options_{};
  double gain_ = 1.0;
  double last_now_s_ = 0.0;
  bool has_last_ = false;
  bool stale_ = false;
};

}  // namespace uh::forcecomp
