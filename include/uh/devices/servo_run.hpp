#pragma once
/// \file
/// ServoRun: one run of a ClockedDevice's servo loop (OpenHaptics' scheduler frames, Haply's
/// replies): the tick and exit callbacks, each frame's TickInfo, a tick that throws, and the
/// frames' timing, kept once for every driver that is its own clock.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <string>

#include "uh/core/fixed_rate_loop.hpp"
#include "uh/core/tick_recorder.hpp"

namespace uh::devices {

/// Threads: begin() from the controlling thread while no frame runs; begin_frame(), tick(),
/// finish_frame() and end() from the servo thread; stats() and missed_deadlines() from any thread.
class ServoRun {
 public:
  using Clock = TickRecorder::Clock;

  /// A new run at `rate_hz` (its frames are counted from 0, its statistics start afresh).
  void begin(double rate_hz, FixedRateLoop::Callback tick, FixedRateLoop::ExitCallback on_exit);
  /// A frame starts at `start`; its grid point was `scheduled`.
  void begin_frame(Clock::time_point scheduled, Clock::time_point start);
  /// Runs the frame's tick. Returns false when the tick threw: the run ends, end() reports why.
  /// Real-time safe but for the throw.
  bool tick();
  /// Records the frame as ended at `end` (a frame later than two periods after the previous one
  /// counts as a missed deadline) and moves to the next.
  void finish_frame(Clock::time_point end);
  /// The run's last act: the exit callback, told whether a tick threw and what.
  void end();

  [[nodiscard]] FixedRateLoopStats stats(bool running) const;
  [[nodiscard]] std::uint64_t missed_deadlines() const { return missed_.load(std::memory_order_relaxed); }
  [[nodiscard]] double rate_hz() const { return rate_hz_; }
  [[nodiscard]] std::chrono::nanoseconds period() const { return period_; }

 private:
  FixedRateLoop::Callback tick_;
  FixedRateLoop::ExitCallback on_exit_;
  double rate_hz_ = 1000.0;
  std::chrono::nanoseconds period_{1'000'000};
  // servo thread
  std::uint64_t index_ = 0;
  Clock::time_point scheduled_{};
  Clock::time_point start_{};
  Clock::time_point previous_start_{};
  LoopExit exit_{};
  std::string thrown_;
  std::atomic<std::uint64_t> missed_{0};
  TickRecorder recorder_;
};

}  // namespace uh::devices
