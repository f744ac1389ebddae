#include "uh/forcecomp/contact_watchdog.hpp"

#include <algorithm>
#include <cmath>

namespace uh::forcecomp {

double ContactWatchdog::update(double now_s, double data_time_s) {
  const double age = now_s - data_time_s;
  stale_ = !std::isfinite(age) || age > options_.max_age_s;
  const double target = stale_ ? 0.0 : 1.0;
  if (!has_last_ || !std::isfinite(now_s)) {
    // first tick: start where the data says, never above it
    gain_ = std::min(gain_, target);
    has_last_ = std::isfinite(now_s);
    last_now_s_ = has_last_ ? now_s : 0.0;
    return gain_;
  }
  const double dt = std::max(0.0, now_s - last_now_s_);
  last_now_s_ = now_s;
  const double ramp = options_.ramp_s > 0.0 ? options_.ramp_s : 1e-9;
  const double step = dt / ramp;
  gain_ = target > gain_ ? std::min(target, gain_ + step) : std::max(target, gain_ - step);
  return gain_;
}

void ContactWatchdog::reset(double gain) {
  gain_ = std::clamp(gain, 0.0, 1.0);
  has_last_ = false;
  stale_ = false;
  last_now_s_ = 0.0;
}

}  // namespace uh::forcecomp
