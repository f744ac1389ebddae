#pragma once
/// \file
/// TickRecorder: the timing statistics of a periodic loop (rate, period jitter, lateness, time in
/// the callback), recorded by the thread that runs the ticks: FixedRateLoop's own thread, or a
/// vendor's servo thread when a device is the clock.

#include <atomic>
#include <chrono>
#include <cstdint>

#include "uh/core/latency_histogram.hpp"

namespace uh {

struct FixedRateLoopStats;

/// Records one entry per tick; fills the timing fields of FixedRateLoopStats.
///
/// Threads: reset() while no thread records; record() from the one ticking thread (real-time
/// safe); fill() and ticks() from any thread (lock-free reads).
class TickRecorder {
 public:
  using Clock = std::chrono::steady_clock;

  void reset();
  /// One tick with deadline `scheduled`, whose callback ran from `start` to `end`; `period` is the
  /// nominal period (the jitter is measured against it).
  void record(Clock::time_point scheduled, Clock::time_point start, Clock::time_point end,
              std::chrono::nanoseconds period);
  /// Sets ticks, elapsed_s, achieved_rate_hz, period_error, lateness and callback_duration of `s`.
  void fill(FixedRateLoopStats& s) const;
  [[nodiscard]] std::uint64_t ticks() const { return ticks_.load(std::memory_order_acquire); }

 private:
  std::atomic<std::uint64_t> ticks_{0};
  std::atomic<std::int64_t> first_start_ns_{0};
  std::atomic<std::int64_t> last_start_ns_{0};
  Clock::time_point previous_start_{};  // recording thread
  LatencyHistogram period_error_;
  LatencyHistogram lateness_;
  LatencyHistogram callback_duration_;
};

}  // namespace uh
