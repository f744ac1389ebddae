#include "uh/core/tick_recorder.hpp"

#include "uh/core/fixed_rate_loop.hpp"

namespace uh {
namespace {

std::int64_t to_ns(TickRecorder::Clock::time_point t) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count();
}

std::uint64_t abs_ns(std::int64_t v) { return static_cast<std::uint64_t>(v < 0 ? -v : v); }

}  // namespace

void TickRecorder::reset() {
  ticks_.store(0, std::memory_order_relaxed);
  first_start_ns_.store(0, std::memory_order_relaxed);
  last_start_ns_.store(0, std::memory_order_relaxed);
  previous_start_ = {};
  period_error_.reset();
  lateness_.reset();
  callback_duration_.reset();
}

void TickRecorder::record(Clock::time_point scheduled, Clock::time_point start, Clock::time_point end,
                          std::chrono::nanoseconds period) {
  lateness_.record(abs_ns((start - scheduled).count()));
  callback_duration_.record(abs_ns((end - start).count()));
  if (ticks_.load(std::memory_order_relaxed) == 0) {
    first_start_ns_.store(to_ns(start), std::memory_order_relaxed);
  } else {
    period_error_.record(abs_ns((start - previous_start_ - period).count()));
  }
  last_start_ns_.store(to_ns(start), std::memory_order_relaxed);
  previous_start_ = start;
  ticks_.fetch_add(1, std::memory_order_release);
}

void TickRecorder::fill(FixedRateLoopStats& s) const {
  s.ticks = ticks_.load(std::memory_order_acquire);
  const std::int64_t first = first_start_ns_.load(std::memory_order_relaxed);
  const std::int64_t last = last_start_ns_.load(std::memory_order_relaxed);
  // ticks and the last start are two atomics: the rate may be off by one tick while the loop runs
  if (s.ticks >= 2 && last > first) {
    s.elapsed_s = static_cast<double>(last - first) * 1e-9;
    s.achieved_rate_hz = static_cast<double>(s.ticks - 1) / s.elapsed_s;
  }
  s.period_error = period_error_.summary();
  s.lateness = lateness_.summary();
  s.callback_duration = callback_duration_.summary();
}

}  // namespace uh
