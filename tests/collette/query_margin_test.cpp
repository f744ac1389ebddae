// VolumeQuery's contact margin: pairs closer than the margin are stored with volume 0, the totals
// stay those of the overlapping pairs; checked against a brute force over all leaf pairs.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <utility>

#include "tree_test_support.hpp"
#include "uh/collette/sphere_tree_builder.hpp"
#include "uh/collette/volume_query.hpp"

namespace uh::collette {
namespace {

using testing::centre;
using testing::make_packing;
using testing::Shape;

TEST(VolumeQueryMargin, StoresExactlyThePairsWithinTheMarginAndKeepsTheTotals) {
  const auto leaves_a = make_packing(0.12, Shape::kBall, 11);
  const auto leaves_b = make_packing(0.09, Shape::kBox, 12);
  const auto a = build_sphere_tree(leaves_a);
  const auto b = build_sphere_tree(leaves_b);
  ASSERT_TRUE(a && b);
  constexpr float kMargin = 0.05f;
  constexpr double kMarginD = static_cast<double>(kMargin);
  VolumeQuery exact;
  VolumeQuery with_margin({.contact_margin = kMargin});
  core::SplitMix64 rng{5};
  int poses_with_near = 0;
  for (int trial = 0; trial < 12; ++trial) {
    const Pose b_in_a = testing::random_pose(rng, 1.6);
    const auto& r0 = exact.run(*a, *b, b_in_a);
    const double volume0 = r0.total_volume;
    const std::int64_t overlapping0 = r0.stats.overlapping_pairs;
    const auto& r = with_margin.run(*a, *b, b_in_a);
    EXPECT_DOUBLE_EQ(r.total_volume, volume0) << "near pairs add nothing to the totals";
    EXPECT_EQ(r.stats.overlapping_pairs, overlapping0);

    // brute force: every leaf pair, in double
    std::set<std::pair<int, int>> overlapping, near, ambiguous;
    for (std::size_t i = 0; i < leaves_a.size(); ++i)
      for (std::size_t j = 0; j < leaves_b.size(); ++j) {
        const double d = norm(transform_point(b_in_a, centre(leaves_b[j])) - centre(leaves_a[i]));
        const double rs = static_cast<double>(leaves_a[i].radius) + static_cast<double>(leaves_b[j].radius);
        // skip pairs within float rounding of either threshold: float and double may disagree there
        if (std::abs(d - rs) < 1e-4 || std::abs(d - rs - kMarginD) < 1e-4) {
          ambiguous.insert({static_cast<int>(i), static_cast<int>(j)});
          continue;
        }
        if (d < rs) overlapping.insert({static_cast<int>(i), static_cast<int>(j)});
        else if (d < rs + kMarginD) near.insert({static_cast<int>(i), static_cast<int>(j)});
      }
    std::set<std::pair<int, int>> got_overlapping, got_near;
    for (const PairOverlap& p : with_margin.pairs()) {
      (p.volume > 0.f ? got_overlapping : got_near).insert({p.leaf_a, p.leaf_b});
      if (p.volume == 0.f) {
        EXPECT_NEAR(std::sqrt(p.normal[0] * p.normal[0] + p.normal[1] * p.normal[1] + p.normal[2] * p.normal[2]), 1.0f, 1e-5f);
      }
    }
    for (const auto& pr : overlapping) EXPECT_TRUE(got_overlapping.count(pr)) << "missing overlapping pair";
    for (const auto& pr : near) EXPECT_TRUE(got_near.count(pr)) << "missing near pair " << pr.first << "," << pr.second;
    EXPECT_EQ(r.near_pairs, static_cast<std::int64_t>(got_near.size()));
    for (const auto& pr : got_near)
      EXPECT_TRUE(near.count(pr) || ambiguous.count(pr)) << "a stored near pair is not within the margin";
    poses_with_near += !near.empty();
  }
  EXPECT_GT(poses_with_near, 3) << "the random poses must exercise the margin";
}

TEST(VolumeQueryMargin, ZeroMarginStoresNoNearPairs) {
  const auto leaves = make_packing(0.15, Shape::kBall, 3);
  const auto tree = build_sphere_tree(leaves);
  ASSERT_TRUE(tree);
  VolumeQuery q;
  const auto& r = q.run(*tree, *tree, Pose{{}, {1.2, 0.1, 0.0}});
  EXPECT_EQ(r.near_pairs, 0);
  for (const PairOverlap& p : q.pairs()) EXPECT_GT(p.volume, 0.f);
}

}  // namespace
}  // namespace uh::collette
