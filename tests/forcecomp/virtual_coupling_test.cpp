#include "uh/forcecomp/virtual_coupling.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace uh::forcecomp {
namespace {

TEST(VirtualCoupling, PassivityBoundMatchesColgateCondition) {
  // b = 1 N s/m: 2 N/mm at 1 kHz, 8 N/mm at 4 kHz
  EXPECT_NEAR(max_passive_stiffness(1.0, 1e-3, 0.0), 2000.0, 1e-9);
  EXPECT_NEAR(max_passive_stiffness(1.0, 0.25e-3, 0.0), 8000.0, 1e-9);
  // b > K T / 2 + |B|: the coupling damper uses up part of the budget, whatever its sign
  EXPECT_NEAR(max_passive_stiffness(1.0, 1e-3, 0.4), 1200.0, 1e-9);
  EXPECT_NEAR(max_passive_stiffness(1.0, 1e-3, -0.4), 1200.0, 1e-9);
  EXPECT_EQ(max_passive_stiffness(1.0, 1e-3, 1.0), 0.0);
  EXPECT_EQ(max_passive_stiffness(1.0, 0.0, 0.0), 0.0);
  EXPECT_EQ(max_passive_stiffness(std::numeric_limits<double>::quiet_NaN(), 1e-3, 0.0), 0.0);
  // check the condition itself just inside and outside the bound
  const double k = max_passive_stiffness(0.7, 5e-4, 0.1);
  EXPECT_GT(0.7, (0.99 * k) * 5e-4 / 2 + 0.1);
  EXPECT_LT(0.7, (1.01 * k) * 5e-4 / 2 + 0.1);
}

TEST(VirtualCoupling, ClampsConfiguredStiffnessToBound) {
  VirtualCoupling too_stiff({.stiffness = 5000.0, .damping = 0.0, .device_damping = 1.0, .period_s = 1e-3,
                             .passivity_margin = 0.9});
  EXPECT_TRUE(too_stiff.stiffness_limited());
  EXPECT_NEAR(too_stiff.stiffness(), 1800.0, 1e-9);
  VirtualCoupling soft({.stiffness = 500.0, .device_damping = 1.0, .period_s = 1e-3});
  EXPECT_FALSE(soft.stiffness_limited());
  EXPECT_EQ(soft.stiffness(), 500.0);
  // at 4 kHz the same request fits
  VirtualCoupling fast({.stiffness = 5000.0, .device_damping = 1.0, .period_s = 0.25e-3});
  EXPECT_FALSE(fast.stiffness_limited());
}

TEST(VirtualCoupling, DeviceFeelsSpringTowardsProxy) {
  VirtualCoupling c({.stiffness = 1000.0, .device_damping = 1.0, .period_s = 1e-3});
  c.reset(Pose{});
  // the hand jumps 1 mm ahead of the proxy: the device is pulled back with K * 1 mm
  const CouplingOutput out = c.step(Pose{Quat{}, {0.001, 0, 0}}, {}, {}, Wrench{}, 1e-3);
  EXPECT_NEAR(out.device_wrench.force.x, -1.0, 1e-12);
  // and the proxy starts following the hand
  EXPECT_GT(out.world_from_proxy.position.x, 0.0);
}

TEST(VirtualCoupling, SettlesSoDeviceFeelsContactForce) {
  // a constant contact force on the proxy, hand held still: at rest the spring carries it all
  VirtualCoupling c({.stiffness = 900.0, .damping = 0.5, .device_damping = 1.0, .period_s = 1e-3,
                     .proxy_mass_kg = 0.05});
  c.reset(Pose{});
  const Wrench contact{{0, 2.0, 0}, {}};
  CouplingOutput out;
  for (int i = 0; i < 20000; ++i) out = c.step(Pose{}, {}, {}, contact, 1e-3);
  EXPECT_NEAR(out.device_wrench.force.y, 2.0, 1e-3);
  EXPECT_NEAR(out.world_from_proxy.position.y, 2.0 / c.stiffness(), 1e-5);
}

TEST(VirtualCoupling, RotationalCouplingTurnsProxyTowardsDevice) {
  VirtualCoupling c({.angular_stiffness = 0.05, .angular_damping = 0.001, .device_angular_damping = 0.01,
                     .period_s = 1e-3, .proxy_inertia_kg_m2 = 1e-4});
  c.reset(Pose{});
  const Pose turned{quat_from_axis_angle({0, 0, 1}, 0.2), {}};
  const CouplingOutput first = c.step(turned, {}, {}, Wrench{}, 1e-3);
  // the device is turned back: torque about -z of K_r * 0.2
  EXPECT_NEAR(first.device_wrench.torque.z, -c.angular_stiffness() * 0.2, 1e-9);
  CouplingOutput out;
  for (int i = 0; i < 20000; ++i) out = c.step(turned, {}, {}, Wrench{}, 1e-3);
  EXPECT_NEAR(rotation_vector(out.world_from_proxy.rotation).z, 0.2, 1e-4);
}

TEST(VirtualCoupling, RotationVectorOfKnownRotations) {
  const Vec3 r = rotation_vector(quat_from_axis_angle({0, 1, 0}, 1.0));
  EXPECT_NEAR(r.y, 1.0, 1e-12);
  // the long way round is folded to the short one
  const Vec3 s = rotation_vector(quat_from_axis_angle({0, 1, 0}, 2 * kPi - 0.5));
  EXPECT_NEAR(s.y, -0.5, 1e-12);
  EXPECT_EQ(rotation_vector(Quat{}), Vec3{});
}

}  // namespace
}  // namespace uh::forcecomp
