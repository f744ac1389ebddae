#include "uh/devices/servo_run.hpp"

#include <cmath>
#include <exception>
#include <utility>

namespace uh::devices {

void ServoRun::begin(double rate_hz, FixedRateLoop::Callback tick, FixedRateLoop::ExitCallback on_exit) {
  tick_ = std::move(tick);
  on_exit_ = std::move(on_exit);
  rate_hz_ = rate_hz;
  period_ = std::chrono::nanoseconds(static_cast<std::int64_t>(std::llround(1e9 / rate_hz)));
  index_ = 0;
  exit_ = {};
  thrown_.clear();
  missed_.store(0, std::memory_order_relaxed);
  recorder_.reset();
}

void ServoRun::begin_frame(Clock::time_point scheduled, Clock::time_point start) {
  scheduled_ = scheduled;
  start_ = start;
}

bool ServoRun::tick() {
  TickInfo info;
  info.index = index_;
  info.grid_index = index_;
  info.scheduled_time = scheduled_;
  info.start_time = start_;
  info.period_s = 1.0 / rate_hz_;
  info.time_s = static_cast<double>(index_) * info.period_s;
  info.dt_s = index_ == 0 ? info.period_s : std::chrono::duration<double>(start_ - previous_start_).count();
  try {
    tick_(info);
  } catch (const std::exception& e) {
    thrown_ = e.what();
    exit_.callback_threw = true;
  } catch (...) {
    thrown_ = "an exception of unknown type";
    exit_.callback_threw = true;
  }
  return !exit_.callback_threw;
}

void ServoRun::finish_frame(Clock::time_point end) {
  if (index_ > 0 && start_ - previous_start_ > 2 * period_) missed_.fetch_add(1, std::memory_order_relaxed);
  recorder_.record(scheduled_, start_, end, period_);
  previous_start_ = start_;
  ++index_;
}

void ServoRun::end() {
  exit_.what = thrown_.c_str();
  try {
    if (on_exit_) on_exit_(exit_);
  } catch (...) {
    // nothing to report to from the servo thread; the drivers turn forces off after this
  }
}

FixedRateLoopStats ServoRun::stats(bool running) const {
  FixedRateLoopStats s;
  recorder_.fill(s);
  s.missed_deadlines = missed_.load(std::memory_order_relaxed);
  s.rate_hz = rate_hz_;
  s.running = running;
  return s;
}

}  // namespace uh::devices
