#include "uh/haptico/force_limiter.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "uh/haptico/trace_sample.hpp"

namespace uh::haptico {
namespace {

DeviceInfo device(double max_force_n, double max_torque_nm) {
  DeviceInfo d;
  d.name = "test";
  d.dof_actuated = 6;
  d.max_force_n = max_force_n;
  d.max_torque_nm = max_torque_nm;
  return d;
}

TEST(ForceLimiter, EffectiveLimitIsTheMinimumOfEveryPermutation) {
  const double values[] = {1.0, 2.0, 3.0};
  int order[] = {0, 1, 2};
  do {
    const double d = values[order[0]], t = values[order[1]], s = values[order[2]];
    const ForceLimiter limiter(device(d, 0.1 * d), {.tool = {t, 0.1 * t}, .safety = {s, 0.1 * s}}, 1000.0);
    EXPECT_EQ(limiter.max_force_n(), std::min({d, t, s}));
    EXPECT_EQ(limiter.max_torque_nm(), 0.1 * std::min({d, t, s}));
  } while (std::next_permutation(order, order + 3));
  // unset tool and safety limits leave the device's
  const ForceLimiter only_device(device(4.0, 0.2), {}, 1000.0);
  EXPECT_EQ(only_device.max_force_n(), 4.0);
  EXPECT_EQ(only_device.max_torque_nm(), 0.2);
  EXPECT_EQ(only_device.max_force_step_n(), 1.0) << "the default rate limit, 1000 N/s at 1 kHz";
  EXPECT_EQ(only_device.max_torque_step_nm(), 0.05);
}

// A random command sequence with jumps, zeros and long holds: every output is within the
// smallest limit, every step within the rate limit, and a held target is reached exactly.
TEST(ForceLimiter, RandomSequenceStaysWithinMagnitudeAndStepBounds) {
  const double rate_hz = 2000.0;
  ForceLimiter limiter(
      device(5.0, 0.3),
      {.tool = {2.5, 0.2}, .rate = {.max_force_n_per_s = 800.0, .max_torque_nm_per_s = 40.0}}, rate_hz);
  const double max_step_f = 800.0 / rate_hz, max_step_t = 40.0 / rate_hz;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-4.0, 4.0);
  std::uniform_int_distribution<int> hold(1, 40);
  DeviceCommand previous{};
  std::uint64_t rate_flags = 0, steps_over = 0;
  for (int segment = 0; segment < 300; ++segment) {
    DeviceCommand target{{u(rng), u(rng), u(rng)}, {0.1 * u(rng), 0.1 * u(rng), 0.1 * u(rng)}};
    const bool zero = segment % 17 == 0;
    for (int k = hold(rng); k > 0; --k) {
      LimitFlags flags = 0;
      DeviceCommand out;
      if (zero) {
        limiter.zero();
        out = {};
      } else {
        out = limiter.apply(target, 1.0, flags);
        EXPECT_LE(norm(out.force), 2.5 * (1 + 1e-12));
        EXPECT_LE(norm(out.torque), 0.2 * (1 + 1e-12));
        EXPECT_LE(norm(out.force - previous.force), max_step_f * (1 + 1e-12));
        EXPECT_LE(norm(out.torque - previous.torque), max_step_t * (1 + 1e-12));
        // reference: a step is limited exactly when the clamped target is farther than a step
        DeviceCommand clamped = target;
        clamp_norm(clamped.force, 2.5);
        clamp_norm(clamped.torque, 0.2);
        const bool over = norm(clamped.force - previous.force) > max_step_f ||
                          norm(clamped.torque - previous.torque) > max_step_t;
        EXPECT_EQ((flags & kTraceRateLimit) != 0, over);
        if (over) ++steps_over;
        if ((flags & kTraceRateLimit) != 0) ++rate_flags;
        EXPECT_EQ((flags & kTraceForceClamped) != 0, norm(target.force) > 2.5);
        EXPECT_EQ((flags & kTraceToolLimit) != 0, norm(target.force) > 2.5 || norm(target.torque) > 0.2);
        EXPECT_EQ(flags & kTraceDeviceLimit, 0u);
      }
      previous = out;
    }
  }
  EXPECT_GT(steps_over, 100u) << "the sequence exercises the rate limit";
  EXPECT_EQ(rate_flags, steps_over);
}

TEST(ForceLimiter, FadeGainScalesAfterTheClampAndBeforeTheRateLimit) {
  ForceLimiter limiter(device(10.0, 1.0), {.safety = {4.0, 1.0}, .rate = {.max_force_n_per_s = kNoLimit}},
                       1000.0);
  LimitFlags flags = 0;
  const DeviceCommand out = limiter.apply({{0, 0, 8.0}, {}}, 0.25, flags);
  EXPECT_EQ(out.force.z, 1.0) << "clamped to 4 N, then a quarter of it";
  EXPECT_EQ(flags, kTraceForceClamped | kTraceSafetyLimit);
}

TEST(ForceLimiter, NoRateLimitWhenTurnedOff) {
  ForceLimiter limiter(device(10.0, 1.0),
                       {.rate = {.max_force_n_per_s = kNoLimit, .max_torque_nm_per_s = kNoLimit}}, 1000.0);
  LimitFlags flags = 0;
  EXPECT_EQ(limiter.apply({{0, 0, 9.0}, {0.9, 0, 0}}, 1.0, flags).force.z, 9.0);
  EXPECT_EQ(flags, 0u);
}

}  // namespace
}  // namespace uh::haptico
