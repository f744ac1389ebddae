#include "uh/forcecomp/penalty_force.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include "pair_reference.hpp"
#include "uh/forcecomp/force_component.hpp"

namespace uh::forcecomp {
namespace {

using test::make_pair;
using test::sphere;

// unit spheres 1.5 apart: d^2 + 2 d r1 - 3 r1^2 + 2 d r2 + 6 r1 r2 - 3 r2^2 = 8.25,
// V = pi * 0.5^2 * 8.25 / (12 * 1.5) = 0.114583... * pi
constexpr double kHandVolume = 0.25 * 8.25 / 18.0 * kPi;

SpherePairContact unit_pair() {
  return make_pair(sphere(0, 0, 0, 1), Pose{}, sphere(1.5, 0, 0, 1), Pose{});
}

TEST(PenaltyForce, SphereSphereForceMatchesHandComputedValue) {
  const SpherePairContact pair = unit_pair();
  ASSERT_NEAR(pair.volume, kHandVolume, 1e-6);
  PenaltyInput in;
  in.law = ForceLaw::kPaper;
  in.force_scale = 100.0;
  in.tool.center_of_mass_world = {1.5, 0, 0};
  const PenaltyResult r = evaluate_penalty(std::span(&pair, 1), in);
  EXPECT_NEAR(r.wrench.force.x, 100.0 * kHandVolume, 1e-4);
  EXPECT_NEAR(r.wrench.force.y, 0.0, 1e-9);
  EXPECT_NEAR(r.wrench.force.z, 0.0, 1e-9);
  // force through the centre of mass: no torque
  EXPECT_NEAR(norm(r.wrench.torque), 0.0, 1e-6);
  EXPECT_EQ(r.pair_count, 1);
  EXPECT_EQ(r.pushing_pairs, 1);
  EXPECT_NEAR(r.total_volume, kHandVolume, 1e-6);
}

TEST(PenaltyForce, TorqueMatchesHandComputedLever) {
  const SpherePairContact pair = unit_pair();
  // symmetric lens: centroid at x = 0.75; centre of mass one unit above it, so the +x force acting
  // below the centre of mass turns the tool about +z with torque f * 1
  ASSERT_NEAR(pair.centroid_world[0], 0.75, 1e-6);
  PenaltyInput in;
  in.law = ForceLaw::kPaper;
  in.force_scale = 100.0;
  in.tool.center_of_mass_world = {1.5, 1.0, 0};
  const PenaltyResult r6 = evaluate_penalty(std::span(&pair, 1), in);
  const double f = 100.0 * kHandVolume;
  EXPECT_NEAR(r6.wrench.torque.x, 0.0, 1e-6);
  EXPECT_NEAR(r6.wrench.torque.y, 0.0, 1e-6);
  EXPECT_NEAR(r6.wrench.torque.z, f, 1e-4);

  in.mode = ForceMode::k3Dof;
  const PenaltyResult r3 = evaluate_penalty(std::span(&pair, 1), in);
  EXPECT_EQ(r3.wrench.torque, Vec3{});
  EXPECT_NEAR(r3.wrench.force.x, f, 1e-4);
}

TEST(PenaltyForce, ToolOnSideAGetsTheOppositeForce) {
  const SpherePairContact pair = unit_pair();
  PenaltyInput in;
  in.law = ForceLaw::kPaper;
  in.force_scale = 100.0;
  in.tool_side = ContactSide::kA;
  const PenaltyResult r = evaluate_penalty(std::span(&pair, 1), in);
  EXPECT_NEAR(r.wrench.force.x, -100.0 * kHandVolume, 1e-4);
}

TEST(PenaltyForce, DampingTermIsVolumeWeightedShareOfEpsD) {
  // two pairs with different volumes along the same normal: the damping shares sum to eps_d * v
  const SpherePairContact p1 = make_pair(sphere(0, 0, 0, 1), Pose{}, sphere(1.5, 0, 0, 1), Pose{});
  const SpherePairContact p2 = make_pair(sphere(0, 5, 0, 1), Pose{}, sphere(1.8, 5, 0, 1), Pose{});
  const std::vector<SpherePairContact> pairs{p1, p2};
  PenaltyInput in;
  in.law = ForceLaw::kPaper;
  in.force_scale = 100.0;
  in.damping = 50.0;
  in.tool.linear_velocity_world = {-0.1, 0, 0};  // pushing further in
  const PenaltyResult r = evaluate_penalty(pairs, in);
  const double v1 = static_cast<double>(p1.volume);
  const double v2 = static_cast<double>(p2.volume);
  const double total = v1 + v2;
  const double f1 = 100.0 * v1 + 50.0 * 0.1 * v1 / total;
  const double f2 = 100.0 * v2 + 50.0 * 0.1 * v2 / total;
  EXPECT_NEAR(r.wrench.force.x, f1 + f2, 1e-4);
  EXPECT_NEAR(r.wrench.force.x - 100.0 * total, 50.0 * 0.1, 1e-4);

  // the other object's velocity counts relative to the tool: both moving together means no damping
  in.other.linear_velocity_world = {-0.1, 0, 0};
  const PenaltyResult same = evaluate_penalty(pairs, in);
  EXPECT_NEAR(same.wrench.force.x, 100.0 * total, 1e-4);
}

TEST(PenaltyForce, DampingFullVolumeRampsTheDampingUpFromContact) {
  // one unit sphere pushed into another along x at 0.1 per second, deeper and deeper: the
  // damping part of the force against the overlap volume
  PenaltyInput paper;
  paper.law = ForceLaw::kPaper;
  paper.force_scale = 100.0;
  paper.damping = 50.0;
  paper.tool.linear_velocity_world = {-0.1, 0, 0};
  PenaltyInput ramped = paper;
  const double full = 0.2;  // V_d
  ramped.damping_full_volume = full;
  double last_damping = 0.0;
  for (double d = 1.999; d > 1.2; d -= 0.01) {
    const SpherePairContact pair = make_pair(sphere(0, 0, 0, 1), Pose{}, sphere(d, 0, 0, 1), Pose{});
    const double v = static_cast<double>(pair.volume);
    ASSERT_GT(v, 0.0);
    const double spring = 100.0 * v;
    const double damping_paper = evaluate_penalty(std::span(&pair, 1), paper).wrench.force.x - spring;
    const double damping_ramped = evaluate_penalty(std::span(&pair, 1), ramped).wrench.force.x - spring;
    // the paper's reading: the full eps_d * v from the first touch on
    EXPECT_NEAR(damping_paper, 5.0, 1e-6) << "d " << d;
    // ramped: eps_d * v * min(1, V / V_d), continuous and non-decreasing with depth
    EXPECT_NEAR(damping_ramped, 5.0 * std::min(1.0, v / full), 1e-6) << "d " << d;
    EXPECT_GE(damping_ramped, last_damping - 1e-12);
    last_damping = damping_ramped;
  }
  EXPECT_NEAR(last_damping, 5.0, 1e-6) << "deep contacts get the full damping";
  // at the first touch the ramped damping is a vanishing share of eps_d * v
  const SpherePairContact grazing = make_pair(sphere(0, 0, 0, 1), Pose{}, sphere(1.999, 0, 0, 1), Pose{});
  EXPECT_LT(evaluate_penalty(std::span(&grazing, 1), ramped).wrench.force.x, 1e-4 * 5.0);
  // a nonsense V_d falls back to the paper's reading
  for (const double bad : {-1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    ramped.damping_full_volume = bad;
    EXPECT_NEAR(evaluate_penalty(std::span(&grazing, 1), ramped).wrench.force.x,
                evaluate_penalty(std::span(&grazing, 1), paper).wrench.force.x, 1e-12);
  }
}

TEST(PenaltyForce, NeverPullsWhenSeparatingFast) {
  const SpherePairContact pair = unit_pair();
  PenaltyInput in;
  in.law = ForceLaw::kPaper;
  in.force_scale = 100.0;
  in.damping = 1000.0;
  in.tool.linear_velocity_world = {10.0, 0, 0};
  const PenaltyResult r = evaluate_penalty(std::span(&pair, 1), in);
  EXPECT_EQ(r.wrench.force, Vec3{});
  EXPECT_EQ(r.pushing_pairs, 0);
  EXPECT_EQ(r.pair_count, 1);
}

TEST(PenaltyForce, ForcePushesObjectsApart) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> pos(-1.0, 1.0);
  std::uniform_real_distribution<double> rad(0.2, 1.0);
  int tested = 0;
  for (int trial = 0; trial < 500; ++trial) {
    const Sphere a = sphere(pos(rng), pos(rng), pos(rng), rad(rng));
    const Sphere b = sphere(pos(rng), pos(rng), pos(rng), rad(rng));
    const SpherePairContact p = make_pair(a, Pose{}, b, Pose{});
    if (!(p.volume > 0.f) || norm(test::centre_of(b) - test::centre_of(a)) < 1e-3) continue;
    ++tested;
    PenaltyInput in;
    in.law = ForceLaw::kPaper;
    in.force_scale = 10.0;
    const Vec3 a_to_b = test::centre_of(b) - test::centre_of(a);
    EXPECT_GT(dot(evaluate_penalty(std::span(&p, 1), in).wrench.force, a_to_b), 0.0);
    in.tool_side = ContactSide::kA;
    EXPECT_LT(dot(evaluate_penalty(std::span(&p, 1), in).wrench.force, a_to_b), 0.0);
  }
  EXPECT_GT(tested, 100);
}

TEST(PenaltyForce, SkipsNonFiniteAndEmptyPairs) {
  std::vector<SpherePairContact> pairs{unit_pair(), unit_pair(), unit_pair()};
  pairs[1].volume = std::numeric_limits<float>::quiet_NaN();
  pairs[2].volume = 0.f;
  PenaltyInput in;
  in.law = ForceLaw::kPaper;
  in.force_scale = 100.0;
  const PenaltyResult r = evaluate_penalty(pairs, in);
  EXPECT_EQ(r.pair_count, 1);
  EXPECT_NEAR(r.wrench.force.x, 100.0 * kHandVolume, 1e-4);
  EXPECT_TRUE(is_finite(r.wrench.force));
}

TEST(PenaltyForce, ContactFrameOverloadUsesValidPairsOnly) {
  auto frame = std::make_unique<ContactFrame>();
  frame->resize_pairs(2);
  frame->pairs()[0] = unit_pair();
  frame->pairs()[1] = unit_pair();  // present in storage but beyond pair_count
  frame->pair_count = 1;
  PenaltyInput in;
  in.law = ForceLaw::kPaper;
  in.force_scale = 100.0;
  EXPECT_NEAR(evaluate_penalty(*frame, in).wrench.force.x, 100.0 * kHandVolume, 1e-4);
}

// A small sphere dropped under gravity on a large static sphere, integrated with the penalty force:
// returns the apex height after the first bounce.
double bounce_apex(double damping, ForceLaw law = ForceLaw::kPaper) {
  const Sphere ground = sphere(0, -1, 0, 1);  // top at y = 0
  const double r = 0.05;
  const double mass = 0.1;
  const double g = 9.81;
  const double dt = 1e-5;
  double y = 0.1 + r;  // bottom 0.1 above the ground
  double v = 0.0;
  bool touched = false;
  bool left = false;
  double apex = -1.0;
  ForceComponentOptions options;
  options.params.law = law;
  options.params.force_scale = 1e7;
  options.params.stiffness = 3e4;  // a spring of about 2 pi r_eff k = 9 N/mm at this sphere pair
  options.params.damping = damping;
  options.mode = ForceMode::k3Dof;
  const ForceComponent tool(options);
  for (int i = 0; i < 400000; ++i) {
    const SpherePairContact p = make_pair(ground, Pose{}, sphere(0, y, 0, r), Pose{});
    BodyMotion self;
    self.center_of_mass_world = {0, y, 0};
    self.linear_velocity_world = {0, v, 0};
    const double f = tool.evaluate(std::span(&p, 1), self).wrench.force.y;
    if (p.volume > 0.f) touched = true;
    if (touched && p.volume == 0.f && v > 0.0) left = true;
    v += dt * (f / mass - g);
    y += dt * v;
    if (left) {
      apex = std::max(apex, y - r);
      if (v < 0.0) break;
    }
  }
  return apex;
}

TEST(PenaltyForce, DampingRemovesEnergyInBouncingSphere) {
  const double start = 0.1;
  const double undamped = bounce_apex(0.0);
  const double damped = bounce_apex(3.0);
  // the undamped penalty is conservative: the sphere comes back (nearly) as high as it started
  EXPECT_GT(undamped, 0.97 * start);
  EXPECT_LT(undamped, 1.01 * start);
  // damping loses energy: m g h falls
  EXPECT_GT(damped, 0.0);
  EXPECT_LT(damped, 0.9 * undamped);
  // the same with the gradient law (minus the gradient of k * overlap volume: conservative too)
  const double undamped_gradient = bounce_apex(0.0, ForceLaw::kGradient);
  const double damped_gradient = bounce_apex(3.0, ForceLaw::kGradient);
  EXPECT_GT(undamped_gradient, 0.97 * start);
  EXPECT_LT(undamped_gradient, 1.01 * start);
  EXPECT_GT(damped_gradient, 0.0);
  EXPECT_LT(damped_gradient, 0.9 * undamped_gradient);
}

TEST(ForceComponent, BodyMotionShiftsVelocityToCentreOfMass) {
  ForceComponentOptions options;
  options.params.center_of_mass_body = {1, 0, 0};
  const ForceComponent c(options);
  Pose pose;
  pose.position = {0, 0, 2};
  pose.rotation = quat_from_axis_angle({0, 0, 1}, kPi / 2);  // body x -> world y
  const BodyMotion m = c.body_motion(pose, {1, 0, 0}, {0, 0, 3});
  EXPECT_NEAR(m.center_of_mass_world.x, 0.0, 1e-12);
  EXPECT_NEAR(m.center_of_mass_world.y, 1.0, 1e-12);
  EXPECT_NEAR(m.center_of_mass_world.z, 2.0, 1e-12);
  // v_com = v_origin + w x (com - origin) = (1,0,0) + (0,0,3) x (0,1,0) = (1 - 3, 0, 0)
  EXPECT_NEAR(m.linear_velocity_world.x, -2.0, 1e-12);
  EXPECT_NEAR(m.linear_velocity_world.y, 0.0, 1e-12);
}

}  // namespace
}  // namespace uh::forcecomp
