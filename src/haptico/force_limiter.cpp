#include "uh/haptico/force_limiter.hpp"

#include <cmath>

#include "uh/haptico/trace_sample.hpp"

namespace uh::haptico {

namespace {

// a limit that is not a number limits nothing; the scene and the device checks keep them positive
double as_limit(double v) { return std::isnan(v) ? kNoLimit : v; }

// moves `v` towards `target` by at most `max_step`; true if the step had to be shortened
bool limit_step(Vec3& v, const Vec3& previous, double max_step) {
  Vec3 step = v - previous;
  if (!clamp_norm(step, max_step)) return false;
  v = previous + step;
  return true;
}

}  // namespace

ForceLimiter::Smallest ForceLimiter::smallest(double device, double tool, double safety) {
  // strict comparisons: a tie goes to the source named first
  Smallest s{as_limit(device), kTraceDeviceLimit};
  if (as_limit(tool) < s.limit) s = {as_limit(tool), kTraceToolLimit};
  if (as_limit(safety) < s.limit) s = {as_limit(safety), kTraceSafetyLimit};
  return s;
}

ForceLimiter::ForceLimiter(const DeviceInfo& device, const ForceLimitOptions& options, double tick_rate_hz)
    : force_(smallest(device.max_force_n, options.tool.max_force_n, options.safety.max_force_n)),
      torque_(smallest(device.max_torque_nm, options.tool.max_torque_nm, options.safety.max_torque_nm)) {
  if (tick_rate_hz > 0.0) {
    max_force_step_n_ = as_limit(options.rate.max_force_n_per_s) / tick_rate_hz;
    max_torque_step_nm_ = as_limit(options.rate.max_torque_nm_per_s) / tick_rate_hz;
  }
}

DeviceCommand ForceLimiter::apply(const DeviceCommand& wanted, double gain, LimitFlags& flags) {
  DeviceCommand out = wanted;
  if (clamp_norm(out.force, force_.limit)) flags |= kTraceForceClamped | force_.flag;
  if (clamp_norm(out.torque, torque_.limit)) flags |= kTraceTorqueClamped | torque_.flag;
  out.force *= gain;
  out.torque *= gain;
  const bool force_step = limit_step(out.force, last_.force, max_force_step_n_);
  const bool torque_step = limit_step(out.torque, last_.torque, max_torque_step_nm_);
  if (force_step || torque_step) flags |= kTraceRateLimit;
  last_ = out;
  return out;
}

}  // namespace uh::haptico
