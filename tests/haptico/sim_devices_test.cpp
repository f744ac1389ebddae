#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "uh/haptico/sim_circle_device.hpp"
#include "uh/haptico/sim_hand_device.hpp"
#include "uh/haptico/sim_line_device.hpp"
#include "uh/haptico/sim_raster_device.hpp"

namespace uh::haptico {
namespace {

void expect_near(const Vec3& a, const Vec3& b, double tol) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

// runs `ticks` ticks (read, then command) and returns the last state read
DeviceState run(SimulatedDevice& device, int ticks, const DeviceCommand& cmd = {}) {
  DeviceState s;
  for (int i = 0; i < ticks; ++i) {
    s = device.read_state();
    device.command(cmd);
  }
  return s;
}

TEST(SimLineDevice, FollowsSegmentAndBounces) {
  SimLineDevice d({.start = {0, 0, 0}, .end = {0.1, 0, 0}, .duration_s = 1.0, .bounce = true});
  EXPECT_EQ(d.read_state().status, DeviceStatus::kNotOpen);
  ASSERT_TRUE(d.open());
  expect_near(d.read_state().position, {0, 0, 0}, 1e-12);
  const DeviceState mid = run(d, 501);  // state read at t = 0.5 s
  EXPECT_NEAR(mid.time_s, 0.5, 1e-9);
  expect_near(mid.position, {0.05, 0, 0}, 1e-9);
  expect_near(mid.linear_velocity, {0.1, 0, 0}, 1e-6);
  const DeviceState back = run(d, 1000);  // t = 1.5 s: on the way back
  expect_near(back.position, {0.05, 0, 0}, 1e-9);
  expect_near(back.linear_velocity, {-0.1, 0, 0}, 1e-6);
}

TEST(SimLineDevice, StaysAtEndWithoutBounce) {
  SimLineDevice d({.start = {0, 0, 0}, .end = {0, 0, -0.02}, .duration_s = 0.1, .bounce = false});
  ASSERT_TRUE(d.open());
  const DeviceState s = run(d, 500);
  expect_near(s.position, {0, 0, -0.02}, 1e-12);
  expect_near(s.linear_velocity, {}, 1e-12);
}

TEST(SimulatedDevice, DeterministicForFixedStep) {
  SimCircleOptions o{.radius = 0.03, .period_s = 0.7};
  SimCircleDevice a(o);
  SimCircleDevice b(o);
  ASSERT_TRUE(a.open());
  ASSERT_TRUE(b.open());
  for (int i = 0; i < 1000; ++i) {
    const DeviceState sa = a.read_state();
    const DeviceState sb = b.read_state();
    ASSERT_EQ(sa.position, sb.position);
    ASSERT_EQ(sa.linear_velocity, sb.linear_velocity);
    ASSERT_EQ(sa.time_s, sb.time_s);
    a.command({});
    b.command({});
  }
  EXPECT_EQ(a.commands(), 1000u);
}

TEST(SimulatedDevice, SaturatesCommandLikeMotors) {
  SimLineDevice d({.device = {.max_force_n = 2.0, .dof_actuated = 3}});
  ASSERT_TRUE(d.open());
  d.command({.force = {0, 30, 40}, .torque = {1, 0, 0}});
  expect_near(d.last_command().force, {0, 1.2, 1.6}, 1e-12);
  EXPECT_EQ(d.last_command().torque, Vec3{});  // a 3-DOF device renders no torque
  EXPECT_EQ(d.info().max_torque_nm, 0.0);
  ASSERT_TRUE(d.close());
  d.command({.force = {1, 0, 0}});  // ignored while closed
  EXPECT_EQ(d.commands(), 1u);
}

TEST(SimCircleDevice, StaysOnCircleAtConstantSpeed) {
  SimCircleDevice d({.center = {0.01, 0.02, 0.03}, .axis = {0, 1, 1}, .radius = 0.02, .period_s = 0.5});
  ASSERT_TRUE(d.open());
  const Vec3 n = normalized(Vec3{0, 1, 1});
  const double speed = 2 * kPi * 0.02 / 0.5;
  for (int i = 0; i < 700; ++i) {
    const DeviceState s = d.read_state();
    const Vec3 r = s.position - Vec3{0.01, 0.02, 0.03};
    ASSERT_NEAR(norm(r), 0.02, 1e-12);
    ASSERT_NEAR(dot(r, n), 0.0, 1e-12);
    ASSERT_NEAR(norm(s.linear_velocity), speed, 1e-5 * speed);
    // right-handed about the axis
    ASSERT_GT(dot(cross(r, s.linear_velocity), n), 0.0);
    d.command({});
  }
}

TEST(SimRasterDevice, SweepsBoxAtDepthWithoutJumps) {
  const SimRasterOptions o{.box_min = {-0.02, -0.01, -0.03}, .box_max = {0.02, 0.01, 0.01}, .depth = 0.004,
                           .lines = 4, .speed = 0.1};
  SimRasterDevice d(o);
  ASSERT_TRUE(d.open());
  ASSERT_EQ(d.waypoints().size(), 8u);
  std::set<long> rows;
  Vec3 previous = d.read_state().position;
  double min_x = 1, max_x = -1;
  // the whole path is 4 * 0.04 + 3 * 0.02/3 = 0.18 m: 1.8 s at 0.1 m/s
  for (int i = 0; i < 2000; ++i) {
    const DeviceState s = d.read_state();
    ASSERT_NEAR(s.position.z, 0.01 - 0.004, 1e-12);
    ASSERT_GE(s.position.x, -0.02 - 1e-12);
    ASSERT_LE(s.position.x, 0.02 + 1e-12);
    ASSERT_LE(norm(s.position - previous), 0.1 * 1e-3 + 1e-9);  // no jump beyond speed * dt
    min_x = std::min(min_x, s.position.x);
    max_x = std::max(max_x, s.position.x);
    rows.insert(std::lround(s.position.y * 1e6));
    previous = s.position;
    d.command({});
  }
  EXPECT_NEAR(min_x, -0.02, 1e-4);
  EXPECT_NEAR(max_x, 0.02, 1e-4);
  for (int line = 0; line < 4; ++line) {
    EXPECT_TRUE(rows.count(std::lround((-0.01 + 0.02 * line / 3.0) * 1e6))) << "line " << line << " not swept";
  }
}

// the hand pushes the handle into a virtual wall z >= wall rendered by the commanded force
struct WallRun {
  Vec3 final_position;
  double early_peak_speed = 0.0;  // |v| max over the first 0.5 s after reaching the wall
  double late_peak_speed = 0.0;   // over the last 0.5 s
};

WallRun push_into_wall(double wall_stiffness, double hand_damping) {
  SimHandDevice d({.device = {.max_force_n = 1e6},
                   .handle_mass_kg = 0.1,
                   .hand_stiffness = 200.0,
                   .hand_damping = hand_damping,
                   .device_damping = 0.5,
                   .target_start = {0, 0, 0},
                   .target_end = {0, 0, -0.03},
                   .duration_s = 0.5});
  EXPECT_TRUE(d.open());
  const double wall = -0.01;
  WallRun out;
  for (int i = 0; i < 3000; ++i) {
    const DeviceState s = d.read_state();
    DeviceCommand cmd;
    if (s.position.z < wall) cmd.force.z = wall_stiffness * (wall - s.position.z);
    d.command(cmd);
    const double speed = norm(s.linear_velocity);
    if (i >= 1000 && i < 1500) out.early_peak_speed = std::max(out.early_peak_speed, speed);
    if (i >= 2500) out.late_peak_speed = std::max(out.late_peak_speed, speed);
    out.final_position = s.position;
  }
  return out;
}

TEST(SimHandDevice, ForceActsBackOnMotion) {
  // free hand: the handle ends at the target
  SimHandDevice free_hand({.target_end = {0, 0, -0.03}, .duration_s = 0.5});
  ASSERT_TRUE(free_hand.open());
  expect_near(run(free_hand, 3000).position, {0, 0, -0.03}, 1e-5);

  // a wall of 800 N/m (inside the passive range for b = 0.5 N s/m at 1 kHz): the handle settles
  // where the hand spring balances the wall, 200 (-0.03 - z) + 800 (-0.01 - z) = 0
  const WallRun stable = push_into_wall(800.0, 3.0);
  EXPECT_NEAR(stable.final_position.z, (200.0 * -0.03 + 800.0 * -0.01) / 1000.0, 1e-5);
  EXPECT_LT(stable.late_peak_speed, 1e-4);
}

TEST(SimHandDevice, BounceMakesAClosedPath) {
  const SimHandOptions o{.target_start = {0, 0, 0.1}, .target_end = {0, 0, 0.05}, .duration_s = 0.5, .bounce = true};
  const SimHandDevice hand(o);
  for (const double cycle : {0.0, 1.0, 7.0}) {
    const double t0 = cycle * 2.0 * o.duration_s;
    expect_near(hand.target_at(t0), o.target_start, 1e-12);
    expect_near(hand.target_at(t0 + 0.25), {0, 0, 0.075}, 1e-12);
    expect_near(hand.target_at(t0 + 0.5), o.target_end, 1e-12);
    expect_near(hand.target_at(t0 + 0.75), {0, 0, 0.075}, 1e-12);
    expect_near(hand.target_velocity_at(t0 + 0.1), {0, 0, -0.1}, 1e-12);
    expect_near(hand.target_velocity_at(t0 + 0.6), {0, 0, 0.1}, 1e-12);
  }
  // a free hand following the closed path comes back to where it started
  SimHandDevice free_hand(SimHandOptions{.target_start = o.target_start, .target_end = o.target_end,
                                         .duration_s = 0.5, .bounce = true});
  ASSERT_TRUE(free_hand.open());
  expect_near(run(free_hand, 4000).position, o.target_start, 2e-3);
  // without bounce the target stays at the end
  const SimHandDevice one_way({.target_start = {0, 0, 0.1}, .target_end = {0, 0, 0.05}, .duration_s = 0.5});
  expect_near(one_way.target_at(3.0), {0, 0, 0.05}, 1e-12);
  expect_near(one_way.target_velocity_at(3.0), {}, 1e-12);
}

TEST(SimHandDevice, InstabilityOfTooStiffWallIsObservable) {
  // far above the passive bound and with no hand damping the sampled wall pumps energy in: the
  // oscillation grows instead of dying out
  const WallRun unstable = push_into_wall(60000.0, 0.0);
  EXPECT_GT(unstable.late_peak_speed, unstable.early_peak_speed);
}

}  // namespace
}  // namespace uh::haptico
