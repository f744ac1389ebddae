#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "tree_test_support.hpp"
#include "uh/collette/sphere_tree_builder.hpp"
#include "uh/collette/time_critical_query.hpp"
#include "uh/collette/volume_query.hpp"

namespace uh::collette {
namespace {

using testing::make_packing;
using testing::Shape;

TEST(TimeCriticalQuery, UnboundedEqualsVolumeQuery) {
  const auto ta = build_sphere_tree(make_packing(0.1, Shape::kBall, 61));
  const auto tb = build_sphere_tree(make_packing(0.09, Shape::kBox, 62));
  ASSERT_TRUE(ta && tb);
  VolumeQuery exact;
  TimeCriticalQuery tc;
  core::SplitMix64 rng{5};
  for (int k = 0; k < 20; ++k) {
    const Pose pose = testing::random_pose(rng, 1.0);
    const VolumeQueryResult e = exact.run(*ta, *tb, pose);
    const TimeCriticalResult& r = tc.run(*ta, *tb, pose);
    EXPECT_TRUE(r.exact);
    EXPECT_EQ(r.pending_pairs, 0);
    EXPECT_EQ(r.pending_volume, 0.0);
    EXPECT_NEAR(r.volume_estimate, e.total_volume, 1e-5 * e.total_volume + 1e-12) << "pose " << k;
    EXPECT_EQ(r.stats.overlapping_pairs, e.stats.overlapping_pairs);
    EXPECT_LT(norm(r.weighted_normal_sum - e.weighted_normal_sum), 1e-4 * e.total_volume + 1e-12);
    EXPECT_LT(norm(r.volume_gradient - e.volume_gradient), 1e-4 * norm(e.volume_gradient) + 1e-12);
    if (e.total_volume > 0.0) {
      EXPECT_LT(norm(r.volume_centroid - e.volume_centroid), 1e-4);
    }
  }
}

// The direction is within 10 degrees from a quarter of the full expansion on a k-means tree, and
// from half of it on a balanced tree (the default), whose leaf-level nodes hold eight leaves each:
// their density model stays coarse until they are expanded (measured: 14 against 8 degrees at a
// quarter, 2 at half).
void expect_converges_as_the_budget_grows(SphereTreeSplit split, int direction_budget_fraction) {
  const auto la = make_packing(0.06, Shape::kBall, 63);
  const auto ta = build_sphere_tree(la, {.split = split});
  ASSERT_TRUE(ta);
  const Pose pose{quat_from_axis_angle({0, 1, 0}, 0.5), {0.9, 0.1, 0.0}};
  VolumeQuery exact;
  const VolumeQueryResult e = exact.run(*ta, *ta, pose);
  ASSERT_GT(e.total_volume, 0.0);
  TimeCriticalQuery tc;
  const std::int64_t full = tc.run(*ta, *ta, pose).stats.node_pairs_visited;
  ASSERT_GT(full, 100);
  // the error over a geometric series of budgets: rough for small budgets (the density model of
  // a node pair is only an expectation), then shrinking steadily once the expansion reaches the
  // leaves, and zero when the heap drains
  double previous = 1e300;
  double first = -1.0;
  for (std::int64_t budget = 1; budget < 2 * full; budget *= 2) {
    const TimeCriticalResult& r = tc.run(*ta, *ta, pose, {.max_expansions = budget});
    const double err = std::abs(r.volume_estimate - e.total_volume) / e.total_volume;
    if (first < 0.0) first = err;
    EXPECT_LE(r.stats.node_pairs_visited, budget);
    EXPECT_LE(r.exact_volume, e.total_volume * (1.0 + 1e-6));
    if (budget >= full / 8) {
      EXPECT_LE(err, previous * 1.05 + 1e-9) << "budget " << budget;
      previous = err;
    }
    if (budget >= full / 2) {
      EXPECT_LT(err, 0.2) << "budget " << budget;
    }
    if (budget >= full) {
      EXPECT_TRUE(r.exact);
      EXPECT_NEAR(err, 0.0, 1e-6);
    } else {
      EXPECT_FALSE(r.exact);
    }
  }
  EXPECT_GT(first, 0.05) << "a one-pair estimate should be rough: the test would prove little";
  // the direction converges too
  const TimeCriticalResult& r = tc.run(*ta, *ta, pose, {.max_expansions = full / direction_budget_fraction});
  EXPECT_GT(dot(r.restoring_direction, e.restoring_direction), std::cos(10.0 * kPi / 180.0));
  // and so does the direction of the gradient law's force
  EXPECT_GT(dot(normalized(-r.volume_gradient), normalized(-e.volume_gradient)),
            std::cos(10.0 * kPi / 180.0));
}

TEST(TimeCriticalQuery, ConvergesAsTheBudgetGrows) {
  expect_converges_as_the_budget_grows(SphereTreeSplit::kBalanced, 2);
  expect_converges_as_the_budget_grows(SphereTreeSplit::kKMeans, 4);
}

TEST(TimeCriticalQuery, TimeBudgetStopsEarly) {
  const auto ta = build_sphere_tree(make_packing(0.05, Shape::kBall, 64));
  ASSERT_TRUE(ta);
  const Pose pose{quat_from_axis_angle({0, 1, 0}, 0.5), {0.5, 0.0, 0.0}};
  TimeCriticalQuery tc;
  const std::int64_t full = tc.run(*ta, *ta, pose).stats.node_pairs_visited;
  const TimeCriticalResult& r = tc.run(*ta, *ta, pose, {.max_seconds = 0.0});
  EXPECT_FALSE(r.exact);
  EXPECT_LE(r.stats.node_pairs_visited, 16);
  EXPECT_LT(r.stats.node_pairs_visited, full);
  EXPECT_GT(r.volume_estimate, 0.0);
}

}  // namespace
}  // namespace uh::collette
