// Frame-to-frame coherence of the volume query (VolumeQueryOptions::coherence_skin): along paths
// of small steps and jumps, a coherent query must give exactly what a fresh traversal gives (and
// both what brute force gives), and it must actually skip the traversal when B moved little.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <utility>
#include <vector>

#include "tree_test_support.hpp"
#include "uh/collette/sphere_tree_builder.hpp"
#include "uh/collette/volume_query.hpp"

namespace uh::collette {
namespace {

using testing::make_packing;
using testing::Shape;

using PairMap = std::map<std::pair<int, int>, float>;  // (leaf a, leaf b) -> stored volume

PairMap pair_map(const VolumeQuery& q) {
  PairMap m;
  for (const PairOverlap& p : q.pairs()) m[{p.leaf_a, p.leaf_b}] = p.volume;
  return m;
}

// A wandering pose of B around A: small steps (a haptic tool between collision frames), with a
// jump every `jump_every` steps that leaves any skin behind.
std::vector<Pose> wandering_path(int steps, double step, int jump_every, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  Vec3 p{0.9, 0.2, -0.1};
  Quat q = quat_from_axis_angle({0, 1, 0}, 0.4);
  std::vector<Pose> path;
  for (int k = 0; k < steps; ++k) {
    const double s = (k % jump_every == jump_every - 1) ? 40.0 * step : step;
    p += s * Vec3{g(rng), g(rng), g(rng)};
    p = p * std::min(1.0, 1.3 / std::max(1e-9, norm(p)));  // stay in contact range
    q = normalized(quat_from_axis_angle(normalized(Vec3{g(rng), g(rng), g(rng)}), 0.5 * s) * q);
    path.push_back({q, p});
  }
  return path;
}

void expect_coherent_equals_traversal(float margin, float skin) {
  const auto la = make_packing(0.12, Shape::kBall, 61);
  const auto lb = make_packing(0.11, Shape::kBox, 62);
  const auto ta = build_sphere_tree(la, {.arity = 8});
  const auto tb = build_sphere_tree(lb, {.arity = 4});
  ASSERT_TRUE(ta && tb);
  VolumeQuery fresh({.contact_margin = margin});
  VolumeQuery coherent({.contact_margin = margin, .coherence_skin = skin});
  int reused = 0, traversed = 0, touching = 0;
  const auto path = wandering_path(400, 0.004, 25, 7);
  for (std::size_t k = 0; k < path.size(); ++k) {
    const VolumeQueryResult f = fresh.run(*ta, *tb, path[k]);
    const VolumeQueryResult& c = coherent.run(*ta, *tb, path[k]);
    (c.reused_candidates ? reused : traversed) += 1;
    if (f.total_volume > 0.0) ++touching;
    ASSERT_EQ(c.stats.overlapping_pairs, f.stats.overlapping_pairs) << "step " << k;
    ASSERT_EQ(c.near_pairs, f.near_pairs) << "step " << k;
    ASSERT_EQ(pair_map(coherent), pair_map(fresh)) << "step " << k << ": pairs or their volumes differ";
    EXPECT_NEAR(c.total_volume, f.total_volume, 1e-12 * f.total_volume + 1e-15) << "step " << k;
    EXPECT_LT(norm(c.volume_gradient - f.volume_gradient), 1e-9 * norm(f.volume_gradient) + 1e-12) << "step " << k;
    EXPECT_LT(norm(c.volume_centroid - f.volume_centroid), 1e-9) << "step " << k;
    if (c.reused_candidates) {
      EXPECT_EQ(c.stats.node_pairs_visited, 0);
      EXPECT_GE(c.candidate_pairs, c.stats.overlapping_pairs + c.near_pairs);
    }
  }
  // the path must exercise both branches, and mostly in contact
  EXPECT_GT(reused, 200) << "the skin was hardly ever reused: the test would prove little";
  EXPECT_GT(traversed, 16) << "jumps must force new traversals";
  EXPECT_GT(touching, 300);
}

TEST(VolumeQueryCoherence, EqualsTraversalAlongAPath) { expect_coherent_equals_traversal(0.f, 0.03f); }

TEST(VolumeQueryCoherence, EqualsTraversalWithContactMargin) { expect_coherent_equals_traversal(0.02f, 0.03f); }

TEST(VolumeQueryCoherence, MatchesBruteForceAfterManySmallSteps) {
  // drift far from where the candidates were kept, one sub-skin step at a time
  const auto la = make_packing(0.13, Shape::kRod, 63);
  const auto lb = make_packing(0.12, Shape::kBall, 64);
  const auto ta = build_sphere_tree(la);
  const auto tb = build_sphere_tree(lb);
  ASSERT_TRUE(ta && tb);
  VolumeQuery coherent({.coherence_skin = 0.05f});
  const Quat turn = quat_from_axis_angle(normalized(Vec3{0.3, 1.0, 0.2}), 0.002);
  Pose pose{quat_from_axis_angle({1, 0, 0}, 0.3), {-1.6, 0.05, 0.0}};
  int reused = 0;
  for (int k = 0; k < 800; ++k) {
    pose = {normalized(turn * pose.rotation), pose.position + Vec3{0.004, 0.0, 0.0005}};
    const VolumeQueryResult& r = coherent.run(*ta, *tb, pose);
    reused += r.reused_candidates ? 1 : 0;
    if (k % 40 != 39) continue;
    const testing::BruteVolume ref = testing::brute_volume(la, lb, pose);
    ASSERT_NEAR(r.total_volume, ref.volume, 1e-4 * ref.volume + 1e-9) << "step " << k;
    EXPECT_LT(norm(r.volume_gradient - ref.gradient), 1e-3 * norm(ref.gradient) + 1e-6) << "step " << k;
  }
  EXPECT_GT(reused, 600);
}

TEST(VolumeQueryCoherence, NewTreesOrResetTraverseAgain) {
  const auto la = make_packing(0.15, Shape::kBall, 65);
  const auto ta = build_sphere_tree(la);
  const auto tb = build_sphere_tree(la);
  ASSERT_TRUE(ta && tb);
  const Pose pose{quat_from_axis_angle({0, 1, 0}, 0.2), {0.7, 0.0, 0.0}};
  VolumeQuery q({.coherence_skin = 0.05f});
  EXPECT_FALSE(q.run(*ta, *ta, pose).reused_candidates);
  EXPECT_TRUE(q.run(*ta, *ta, pose).reused_candidates);
  EXPECT_FALSE(q.run(*ta, *tb, pose).reused_candidates) << "a different tree B must not reuse A-A candidates";
  EXPECT_TRUE(q.run(*ta, *tb, pose).reused_candidates);
  q.reset_coherence();
  EXPECT_FALSE(q.run(*ta, *tb, pose).reused_candidates);
  // a rotation alone that moves B's far points by more than the skin
  const Pose turned{quat_from_axis_angle({0, 1, 0}, 0.3), pose.position};
  EXPECT_FALSE(q.run(*ta, *tb, turned).reused_candidates);
  // without a skin, never
  VolumeQuery plain;
  plain.run(*ta, *ta, pose);
  EXPECT_FALSE(plain.run(*ta, *ta, pose).reused_candidates);
}

TEST(VolumeQueryCoherence, InvalidSkinMeansNoCoherence) {
  const auto la = make_packing(0.15, Shape::kBall, 66);
  const auto ta = build_sphere_tree(la);
  ASSERT_TRUE(ta);
  const Pose pose{{}, {0.8, 0.0, 0.0}};
  for (const float skin : {-1.f, std::nanf(""), 0.f}) {
    VolumeQuery q({.coherence_skin = skin});
    EXPECT_EQ(q.options().coherence_skin, 0.f);
    q.run(*ta, *ta, pose);
    EXPECT_FALSE(q.run(*ta, *ta, pose).reused_candidates);
  }
}

}  // namespace
}  // namespace uh::collette
