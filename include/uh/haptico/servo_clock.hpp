#pragma once
/// \file
/// ServoClock and ClockedDevice: a device whose vendor runtime owns the servo thread (OpenHaptics'
/// scheduler) is the haptic clock; the HapticManager runs its tick inside the vendor's servo
/// callback instead of on its own FixedRateLoop.

#include <cstdint>

#include "uh/core/fixed_rate_loop.hpp"
#include "uh/core/result.hpp"
#include "uh/haptico/haptic_device.hpp"

namespace uh::haptico {

/// The servo loop of a ClockedDevice, with FixedRateLoop's contract: start() makes the vendor's
/// servo thread call `tick` once per servo frame (between the frame's state reads and its force
/// write, so read_state() and command() called from the tick belong to that frame); the loop ends
/// on stop() or when `tick` throws, and `on_exit` runs once, on the servo thread and inside a
/// frame where the runtime still allows it, before the loop is over.
///
/// Threads: start() and stop() from the controlling thread; running(), stats() and
/// missed_deadlines() from any thread.
class ServoClock {
 public:
  virtual ~ServoClock() = default;
  /// Starts ticking at `rate_hz` (the device open). An Error when the runtime refuses.
  virtual Status start(double rate_hz, FixedRateLoop::Callback tick, FixedRateLoop::ExitCallback on_exit) = 0;
  /// Ends the loop (the current frame finishes, then `on_exit` runs) and waits for it; a servo
  /// thread that no longer answers is given up on after a bounded wait, forces off. Idempotent.
  virtual void stop() = 0;
  [[nodiscard]] virtual bool running() const = 0;
  /// Timing of the servo frames since start() (the device's own rate and jitter).
  [[nodiscard]] virtual FixedRateLoopStats stats() const = 0;
  [[nodiscard]] virtual std::uint64_t missed_deadlines() const = 0;

 protected:
  ServoClock() = default;
  ServoClock(const ServoClock&) = default;
  ServoClock& operator=(const ServoClock&) = default;
};

/// A HapticDevice that brings its own clock. Outside its servo frames (stepped sessions, close())
/// read_state() and command() still work: the driver runs each as one frame of its own.
class ClockedDevice : public HapticDevice {
 public:
  virtual ServoClock& servo_clock() = 0;
};

}  // namespace uh::haptico
