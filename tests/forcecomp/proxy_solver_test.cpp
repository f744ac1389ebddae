#include "uh/forcecomp/proxy_solver.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "allocation_counter.hpp"

namespace uh::forcecomp {
namespace {

using Vec6d = Eigen::Matrix<double, 6, 1>;

// One constraint as a row of the scaled problem min 1/2 |y - y*|^2, a . y >= b, y = (t, R w).
void scaled_row(const ProxyConstraint& c, double radius, Vec6d& a, double& b) {
  const Vec3 turn = cross(c.lever, c.normal);
  a << c.normal.x, c.normal.y, c.normal.z, turn.x / radius, turn.y / radius, turn.z / radius;
  b = -c.gap;
}

// The brute-force reference: every subset of at most six constraints taken as the active set,
// its equality-constrained projection solved with Eigen (an SVD, not the solver's Cholesky), and
// the one that is feasible with non-negative multipliers (the KKT point, unique for this strictly
// convex problem) returned. Exponential, fine for a dozen constraints.
bool brute_force(const std::vector<ProxyConstraint>& cs, const Vec6d& wanted, double radius, Vec6d& best) {
  const std::size_t n = cs.size();
  std::vector<Vec6d> a(n);
  std::vector<double> b(n);
  for (std::size_t k = 0; k < n; ++k) scaled_row(cs[k], radius, a[k], b[k]);
  bool found = false;
  double best_cost = std::numeric_limits<double>::infinity();
  for (std::uint32_t mask = 0; mask < (1u << n); ++mask) {
    const int q = __builtin_popcount(mask);
    if (q > 6) continue;
    Eigen::MatrixXd N(q, 6);
    Eigen::VectorXd rhs(q);
    int row = 0;
    for (std::size_t k = 0; k < n; ++k)
      if (mask & (1u << k)) {
        N.row(row) = a[k].transpose();
        rhs(row) = b[k] - a[k].dot(wanted);
        ++row;
      }
    Vec6d y = wanted;
    Eigen::VectorXd mu;
    if (q > 0) {
      const Eigen::MatrixXd G = N * N.transpose();
      Eigen::JacobiSVD<Eigen::MatrixXd> svd(G, Eigen::ComputeThinU | Eigen::ComputeThinV);
      if (svd.singularValues()(q - 1) < 1e-10 * svd.singularValues()(0)) continue;  // dependent rows
      mu = svd.solve(rhs);
      if ((G * mu - rhs).norm() > 1e-9) continue;
      if (mu.minCoeff() < -1e-9) continue;
      y = wanted + N.transpose() * mu;
    }
    bool feasible = true;
    for (std::size_t k = 0; k < n; ++k) feasible &= a[k].dot(y) >= b[k] - 1e-9;
    if (!feasible) continue;
    const double cost = (y - wanted).squaredNorm();
    if (cost < best_cost) {
      best_cost = cost;
      best = y;
      found = true;
    }
  }
  return found;
}

Vec3 random_unit(std::mt19937& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  return normalized(Vec3{g(rng), g(rng), g(rng)});
}

TEST(ProxySolver, MatchesTheBruteForceActiveSetOnRandomProblems) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double radius = 0.01;
  ProxySolver solver({.radius_m = radius});
  int constrained = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const int n = 1 + trial % 10;
    std::vector<ProxyConstraint> cs;
    for (int k = 0; k < n; ++k) {
      const double v = u(rng);
      cs.push_back({.normal = random_unit(rng),
                    .lever = Vec3{u(rng), u(rng), u(rng)} * radius,
                    .gap = 0.001 * (0.1 + v * v)});  // > 0: the step 0 meets them all
    }
    const Vec3 t{0.003 * u(rng), 0.003 * u(rng), 0.003 * u(rng)};
    const Vec3 w{0.3 * u(rng), 0.3 * u(rng), 0.3 * u(rng)};
    Vec6d wanted;
    wanted << t.x, t.y, t.z, radius * w.x, radius * w.y, radius * w.z;
    Vec6d reference;
    ASSERT_TRUE(brute_force(cs, wanted, radius, reference)) << "trial " << trial;
    const ProxyStep step = solver.solve(cs, t, w);
    ASSERT_TRUE(step.converged) << "trial " << trial;
    Vec6d y;
    y << step.translation.x, step.translation.y, step.translation.z, radius * step.rotation.x,
        radius * step.rotation.y, radius * step.rotation.z;
    EXPECT_LT((y - reference).norm(), 1e-9) << "trial " << trial << " with " << n << " constraints";
    constrained += step.active > 0;
  }
  EXPECT_GT(constrained, 150);  // most problems had a constraint in the way
}

TEST(ProxySolver, StartsFromTooDeepAndPushesOut) {
  // a constraint already violated (gap < 0): the step 0 is not feasible, the solution pushes out
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double radius = 0.02;
  ProxySolver solver({.radius_m = radius});
  for (int trial = 0; trial < 100; ++trial) {
    std::vector<ProxyConstraint> cs;
    for (int k = 0; k < 4; ++k)
      cs.push_back({.normal = random_unit(rng), .lever = Vec3{u(rng), u(rng), u(rng)} * radius, .gap = 0.0005 * u(rng)});
    const Vec3 t{0.002 * u(rng), 0.002 * u(rng), 0.002 * u(rng)};
    const Vec3 w{};
    Vec6d wanted = Vec6d::Zero();
    wanted.head<3>() << t.x, t.y, t.z;
    Vec6d reference;
    const bool feasible = brute_force(cs, wanted, radius, reference);
    const ProxyStep step = solver.solve(cs, t, w);
    if (!feasible) continue;  // four half-spaces in six dimensions always meet; kept for safety
    ASSERT_TRUE(step.converged);
    Vec6d y;
    y << step.translation.x, step.translation.y, step.translation.z, radius * step.rotation.x,
        radius * step.rotation.y, radius * step.rotation.z;
    EXPECT_LT((y - reference).norm(), 1e-9) << "trial " << trial;
  }
}

TEST(ProxySolver, AFlatFloorStopsTheFallAndLetsItSlide) {
  // many pairs under a flat face, all with normal +z: pressing down and sideways slides along
  std::vector<ProxyConstraint> cs;
  for (int i = 0; i < 200; ++i)
    cs.push_back({.normal = {0, 0, 1}, .lever = {0.001 * (i % 10) - 0.005, 0.001 * (i / 10 % 10) - 0.005, -0.005},
                  .gap = 0.0002});
  ProxySolver solver({.radius_m = 0.005});
  const ProxyStep step = solver.solve(cs, {0.001, -0.0005, -0.01}, {});
  ASSERT_TRUE(step.converged);
  EXPECT_NEAR(step.translation.z, -0.0002, 1e-12);
  // the slide is free in x and y, and a tilt is only taken where it does not dig in
  EXPECT_NEAR(step.translation.x, 0.001, 1e-6);
  EXPECT_NEAR(step.translation.y, -0.0005, 1e-6);
  for (const ProxyConstraint& c : cs)
    EXPECT_GE(dot(c.normal, step.translation) + dot(cross(c.lever, c.normal), step.rotation), -c.gap - 1e-12);
}

TEST(ProxySolver, FixedRotationConstrainsTheTranslationOnly) {
  const ProxyConstraint c{.normal = {0, 0, 1}, .lever = {0.01, 0, 0}, .gap = 0.0};
  ProxySolver solver({.radius_m = 0.01, .rotate = false});
  const Vec3 w{0, 0.1, 0};  // turning about y lowers the contact point at +x by 0.01 * 0.1
  const ProxyStep step = solver.solve({&c, 1}, {0, 0, 0}, w);
  EXPECT_EQ(step.rotation.y, 0.1);
  EXPECT_NEAR(step.translation.z, 0.001, 1e-12);  // lifted by what the turn lowers the contact
}

TEST(ProxySolver, OpposedFacesTooDeepAreReportedNotSolved) {
  // pinched between two faces, each already 1 mm too deep: no step meets both
  const ProxyConstraint cs[2] = {{.normal = {0, 0, 1}, .lever = {}, .gap = -0.001},
                                 {.normal = {0, 0, -1}, .lever = {}, .gap = -0.001}};
  ProxySolver solver({.radius_m = 0.01, .rotate = false});
  const ProxyStep step = solver.solve(cs, {}, {});
  EXPECT_FALSE(step.converged);
  EXPECT_TRUE(is_finite(step.translation));
}

TEST(ProxySolver, SolveDoesNotAllocate) {
  std::vector<ProxyConstraint> cs;
  std::mt19937 rng(3);
  for (int i = 0; i < 500; ++i) cs.push_back({.normal = random_unit(rng), .lever = {0.001, 0.002, 0.0}, .gap = 0.001});
  ProxySolver solver({.radius_m = 0.01});
  const test::AllocationCounter allocations;
  const ProxyStep step = solver.solve(cs, {0.01, 0.0, -0.01}, {0.1, 0.0, 0.0});
  EXPECT_EQ(allocations.count(), 0u);
  EXPECT_TRUE(is_finite(step.translation));
}

}  // namespace
}  // namespace uh::forcecomp
