// The gradient force law against independent references: central finite differences of the
// brute-force overlap volume (every sphere pair of two packings, the textbook lens volume in long
// double, tests/support/lens_reference.hpp), not the law's own disk-area formula; the work it does
// around a closed path; its calibration by the packings' coverages.

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <span>
#include <vector>

#include "pair_reference.hpp"
#include "uh/forcecomp/force_component.hpp"
#include "uh/forcecomp/penalty_force.hpp"

namespace uh::forcecomp {
namespace {

using test::brute_force_pairs;
using test::sphere;

// Disjoint spheres (a packing) of radii 0.05..0.15 in a box of half size `half`, by rejection.
std::vector<Sphere> random_packing(std::mt19937& rng, int count, double half) {
  std::uniform_real_distribution<double> pos(-half, half);
  std::uniform_real_distribution<double> rad(0.05, 0.15);
  std::vector<Sphere> out;
  for (int tries = 0; tries < 100000 && static_cast<int>(out.size()) < count; ++tries) {
    const Sphere s = sphere(pos(rng), pos(rng), pos(rng), rad(rng));
    bool free = true;
    for (const Sphere& o : out)
      free =
          free && norm(test::centre_of(s) - test::centre_of(o)) >= static_cast<double>(s.radius + o.radius);
    if (free) out.push_back(s);
  }
  return out;
}

// Sum over every pair of A's and B's spheres of the reference lens volume: the packings' overlap.
double overlap_volume(const std::vector<Sphere>& a, const std::vector<Sphere>& b, const Pose& world_from_b) {
  double v = 0.0;
  for (const Sphere& sa : a)
    for (const Sphere& sb : b) {
      const double d = norm(transform_point(world_from_b, test::centre_of(sb)) - test::centre_of(sa));
      v += uh::test::lens_reference(d, static_cast<double>(sa.radius), static_cast<double>(sb.radius)).volume;
    }
  return v;
}

// world_from_b turned by `angle` about `axis` through `pivot` (world frame).
Pose turned(const Pose& world_from_b, const Vec3& axis, double angle, const Vec3& pivot) {
  const Quat q = quat_from_axis_angle(axis, angle);
  return Pose{q * world_from_b.rotation, pivot + rotate(q, world_from_b.position - pivot)};
}

TEST(GradientLaw, ForceAndTorqueAreMinusTheGradientOfStiffnessTimesOverlapVolume) {
  std::mt19937 rng(21);
  const std::vector<Sphere> a = random_packing(rng, 40, 0.5);
  const std::vector<Sphere> b = random_packing(rng, 40, 0.5);
  ASSERT_EQ(a.size(), 40u);
  ASSERT_EQ(b.size(), 40u);
  const double k = 250.0;
  int poses = 0;
  for (const Pose& world_from_b : {Pose{quat_from_axis_angle({1, 2, 3}, 0.4), {0.45, -0.1, 0.2}},
                                   Pose{quat_from_axis_angle({0, 1, -1}, 1.1), {0.1, 0.3, -0.35}},
                                   Pose{quat_from_axis_angle({1, 0, 0}, -0.7), {-0.6, 0.05, 0.0}}}) {
    const std::vector<SpherePairContact> pairs = brute_force_pairs(a, Pose{}, b, world_from_b);
    if (pairs.size() < 5u) continue;
    ++poses;
    PenaltyInput in;
    in.law = ForceLaw::kGradient;
    in.stiffness = k;
    in.tool.center_of_mass_world = world_from_b.position + Vec3{0.03, -0.02, 0.05};
    const PenaltyResult r = evaluate_penalty(pairs, in);

    const double h = 1e-5;
    Vec3 grad_x{}, grad_w{};  // dV / d(translation of B), dV / d(rotation of B about its centre of mass)
    for (int axis = 0; axis < 3; ++axis) {
      Vec3 e{};
      (axis == 0 ? e.x : axis == 1 ? e.y : e.z) = 1.0;
      const double dx = (overlap_volume(a, b, Pose{world_from_b.rotation, world_from_b.position + h * e}) -
                         overlap_volume(a, b, Pose{world_from_b.rotation, world_from_b.position - h * e})) /
                        (2 * h);
      const double dw = (overlap_volume(a, b, turned(world_from_b, e, h, in.tool.center_of_mass_world)) -
                         overlap_volume(a, b, turned(world_from_b, e, -h, in.tool.center_of_mass_world))) /
                        (2 * h);
      (axis == 0 ? grad_x.x : axis == 1 ? grad_x.y : grad_x.z) = dx;
      (axis == 0 ? grad_w.x : axis == 1 ? grad_w.y : grad_w.z) = dw;
    }
    const Vec3 force = -k * grad_x, torque = -k * grad_w;
    ASSERT_GT(norm(force), 0.0);
    // float storage of the pair records (area, normal, centroid) limits the agreement to ~1e-6
    EXPECT_LT(norm(r.wrench.force - force), 1e-4 * norm(force)) << "pose " << poses;
    EXPECT_LT(norm(r.wrench.torque - torque), 1e-4 * norm(torque) + 1e-6 * norm(force)) << "pose " << poses;
  }
  EXPECT_EQ(poses, 3) << "every pose must overlap";
}

TEST(GradientLaw, DoesNoWorkAroundAClosedPath) {
  // B circles through A (translation only, so the torque does no work): the work of a conservative
  // force around a closed loop is zero; the trapezoid rule's error is far below the tolerance
  std::mt19937 rng(5);
  const std::vector<Sphere> a = random_packing(rng, 30, 0.4);
  const std::vector<Sphere> b = random_packing(rng, 30, 0.3);
  PenaltyInput in;
  in.stiffness = 100.0;
  constexpr int kSteps = 4000;
  const auto position = [](int i) {
    const double t = 2 * kPi * i / kSteps;
    return Vec3{0.35 * std::cos(t), 0.35 * std::sin(t), 0.1 * std::sin(2 * t)};
  };
  const Quat rotation = quat_from_axis_angle({1, 1, 0}, 0.3);
  double work = 0.0, scale = 0.0;
  Vec3 last{};
  for (int i = 0; i <= kSteps; ++i) {
    const Vec3 f =
        evaluate_penalty(brute_force_pairs(a, Pose{}, b, Pose{rotation, position(i)}), in).wrench.force;
    if (i > 0) {
      const Vec3 dx = position(i) - position(i - 1);
      work += 0.5 * dot(f + last, dx);
      scale += 0.5 * (norm(f) + norm(last)) * norm(dx);
    }
    last = f;
  }
  ASSERT_GT(scale, 0.0);
  EXPECT_LT(std::abs(work), 1e-3 * scale) << "work " << work << " of " << scale;
}

TEST(GradientLaw, IsCalibratedByTheCoverageProductAndThePaperLawIsNot) {
  std::mt19937 rng(8);
  const std::vector<Sphere> a = random_packing(rng, 20, 0.4);
  const std::vector<Sphere> b = random_packing(rng, 20, 0.4);
  const std::vector<SpherePairContact> pairs = brute_force_pairs(a, Pose{}, b, Pose{{}, {0.3, 0.1, 0}});
  ASSERT_GT(pairs.size(), 3u);
  PenaltyInput in;
  in.stiffness = 100.0;
  in.force_scale = 1000.0;
  const Vec3 uncalibrated = evaluate_penalty(pairs, in).wrench.force;
  in.coverage_product = 0.64;
  EXPECT_LT(norm(evaluate_penalty(pairs, in).wrench.force - uncalibrated / 0.64), 1e-12 * norm(uncalibrated));
  for (const double unknown : {0.0, -1.0, std::nan("")}) {
    in.coverage_product = unknown;
    EXPECT_EQ(evaluate_penalty(pairs, in).wrench.force, uncalibrated) << unknown;
  }
  in.law = ForceLaw::kPaper;
  in.coverage_product = 1.0;
  const Vec3 paper = evaluate_penalty(pairs, in).wrench.force;
  in.coverage_product = 0.64;
  EXPECT_EQ(evaluate_penalty(pairs, in).wrench.force, paper);
}

TEST(GradientLaw, DampingRampComparesTheCalibratedVolume) {
  // one pair pushed in at 0.1/s: damping eps_d v min(1, (V / c) / V_d)
  PenaltyInput in;
  in.stiffness = 0.0;  // damping alone
  in.damping = 50.0;
  in.damping_full_volume = 0.2;
  in.coverage_product = 0.5;
  in.tool.linear_velocity_world = {-0.1, 0, 0};
  for (double d = 1.95; d > 1.3; d -= 0.05) {
    const SpherePairContact pair = test::make_pair(sphere(0, 0, 0, 1), Pose{}, sphere(d, 0, 0, 1), Pose{});
    const double v = static_cast<double>(pair.volume);
    EXPECT_NEAR(evaluate_penalty(std::span(&pair, 1), in).wrench.force.x, 5.0 * std::min(1.0, v / 0.5 / 0.2),
                1e-9)
        << "d " << d;
  }
}

TEST(GradientLaw, ForceComponentCarriesTheLawAndStiffness) {
  const SpherePairContact pair = test::make_pair(sphere(0, 0, 0, 1), Pose{}, sphere(1.5, 0, 0, 1), Pose{});
  ForceComponentOptions options;
  options.params.stiffness = 40.0;
  options.params.damping = 0.0;
  const ForceComponent gradient(options);
  const BodyMotion self = gradient.body_motion(Pose{{}, {1.5, 0, 0}}, {}, {});
  // unit spheres 1.5 apart: intersection disk radius^2 = 1 - 0.75^2
  EXPECT_NEAR(gradient.evaluate(std::span(&pair, 1), self, {}, 0.8).wrench.force.x,
              40.0 / 0.8 * kPi * (1.0 - 0.75 * 0.75), 1e-4);
  options.params.law = ForceLaw::kPaper;
  options.params.force_scale = 40.0;
  EXPECT_NEAR(ForceComponent(options).evaluate(std::span(&pair, 1), self, {}, 0.8).wrench.force.x,
              40.0 * static_cast<double>(pair.volume), 1e-6);
}

}  // namespace
}  // namespace uh::forcecomp
