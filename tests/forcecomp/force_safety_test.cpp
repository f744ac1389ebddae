#include "uh/forcecomp/force_safety.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace uh::forcecomp {
namespace {

Wrench wrench(Vec3 f, Vec3 t = {}) { return Wrench{f, t}; }

TEST(ForceSafety, AppliesNoMagnitudeLimit) {
  // limits belong to the haptic manager's one chain (haptico::ForceLimiter), not to this stage
  ForceSafety safety;
  const Wrench out = safety.apply(wrench({300, 400, 0}, {0, 0, -10}), 0.0, 0.0);
  EXPECT_EQ(out.force, (Vec3{300, 400, 0}));
  EXPECT_EQ(out.torque, (Vec3{0, 0, -10}));
  EXPECT_EQ(safety.counters().ticks, 1u);
}

TEST(ForceSafety, NonFiniteReplacedByZeroAndCounted) {
  ForceSafety safety;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(safety.apply(wrench({nan, 1, 1}), 0.0, 0.0).force, Vec3{});
  const Wrench t = safety.apply(wrench({1, 1, 1}, {0, inf, 0}), 0.001, 0.001);
  EXPECT_EQ(t.force, Vec3{});
  EXPECT_EQ(t.torque, Vec3{});
  EXPECT_EQ(safety.counters().nonfinite, 2u);
}

TEST(ForceSafety, WatchdogRampsForceToZeroWhenDataStale) {
  ForceSafety safety({.watchdog = {.max_age_s = 0.01, .ramp_s = 0.1}});
  const double data_time = 0.0;
  const Vec3 f{10, 0, 0};
  // fresh data: full force
  EXPECT_EQ(safety.apply(wrench(f), 0.005, data_time).force.x, 10.0);
  EXPECT_EQ(safety.apply(wrench(f), 0.010, data_time).force.x, 10.0);
  // stale from here on (collision thread stalled): the gain falls 1 per ramp_s, never a step
  double previous = 10.0;
  double t = 0.010;
  for (int i = 0; i < 150; ++i) {
    t += 0.001;
    const double now = safety.apply(wrench(f), t, data_time).force.x;
    EXPECT_LE(now, previous);
    EXPECT_GE(now, previous - 10.0 * 0.001 / 0.1 - 1e-9);  // at most one ramp step per tick
    previous = now;
    if (i == 49) {
      EXPECT_NEAR(now, 5.0, 1e-6);  // half the ramp: half the force
    }
  }
  EXPECT_EQ(previous, 0.0);
  EXPECT_EQ(safety.counters().stale_ticks, 150u);
}

TEST(ForceSafety, WatchdogRampsBackUpWithoutStep) {
  ContactWatchdog dog({.max_age_s = 0.01, .ramp_s = 0.1});
  dog.update(0.0, 0.0);
  for (int i = 1; i <= 200; ++i) dog.update(0.001 * i, 0.0);  // stale for long
  EXPECT_EQ(dog.gain(), 0.0);
  EXPECT_TRUE(dog.stale());
  // fresh data arrives: the gain climbs at the same bounded rate
  EXPECT_NEAR(dog.update(0.201, 0.2), 0.01, 1e-9);
  EXPECT_FALSE(dog.stale());
  for (int i = 2; i <= 100; ++i) dog.update(0.2 + 0.001 * i, 0.2 + 0.001 * i);
  EXPECT_NEAR(dog.gain(), 1.0, 1e-9);
}

TEST(ForceSafety, NonFiniteDataTimeCountsAsStale) {
  ContactWatchdog dog;
  EXPECT_EQ(dog.update(1.0, std::numeric_limits<double>::quiet_NaN()), 0.0);
  EXPECT_TRUE(dog.stale());
}

TEST(ForceSafety, StopZeroesAndResumeFadesIn) {
  ForceSafety safety({.watchdog = {.max_age_s = 1.0, .ramp_s = 0.01}});
  EXPECT_EQ(safety.apply(wrench({10, 0, 0}), 0.0, 0.0).force.x, 10.0);
  safety.stop();
  EXPECT_TRUE(safety.stopped());
  for (int i = 1; i <= 5; ++i) EXPECT_EQ(safety.apply(wrench({10, 0, 0}, {0.1, 0, 0}), 0.001 * i, 0.0).force, Vec3{});
  EXPECT_EQ(safety.counters().zeroed_ticks, 5u);
  safety.resume();
  // no step back to full force after a stop
  const double first = safety.apply(wrench({10, 0, 0}), 0.006, 0.006).force.x;
  EXPECT_LT(first, 10.0);
  for (int i = 7; i <= 30; ++i) safety.apply(wrench({10, 0, 0}), 0.001 * i, 0.001 * i);
  EXPECT_NEAR(safety.apply(wrench({10, 0, 0}), 0.031, 0.031).force.x, 10.0, 1e-9);
}

TEST(ForceSafety, DeviceFaultZeroesUntilResume) {
  ForceSafety safety;
  safety.report_fault();
  EXPECT_TRUE(safety.faulted());
  EXPECT_EQ(safety.apply(wrench({1, 0, 0}), 0.0, 0.0).force, Vec3{});
  safety.resume();
  EXPECT_FALSE(safety.faulted());
}

}  // namespace
}  // namespace uh::forcecomp
