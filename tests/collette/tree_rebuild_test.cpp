// A tree rebuilt where its leaves are now (rebuild_sphere_tree, for a deformable object whose refit
// has grown loose): a box packing sheared until its top has moved twice the box's height, then
// refitted (the topology of rest) and rebuilt (regrouped where the leaves are). Checked against
// references the rebuild does not compute: validate(), a fresh build over the moved leaves, the
// node spheres summed here node by node, and the volume query's pairs and volume against brute
// force over all leaf pairs.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <set>
#include <utility>
#include <vector>

#include "tree_test_support.hpp"
#include "uh/collette/sphere_tree.hpp"
#include "uh/collette/sphere_tree_builder.hpp"
#include "uh/collette/volume_query.hpp"

namespace uh::collette {
namespace {

using testing::brute_volume;
using testing::make_packing;
using testing::Shape;

// the box packing (2 x 1.2 x 0.8) sheared: x moved by `shear` times z
std::vector<Sphere> sheared(std::vector<Sphere> leaves, float shear) {
  for (Sphere& s : leaves) s.x += shear * s.z;
  return leaves;
}

// the sphere volumes of the nodes whose children are all leaves (the trees here are balanced),
// found here by their leaves' parent links
double inner_volume_by_hand(const SphereTree& tree) {
  std::set<std::int32_t> parents;
  for (const SphereTreeNode& n : tree.nodes())
    if (n.is_leaf()) parents.insert(n.parent);
  double sum = 0.0;
  for (std::int32_t p : parents)
    sum += 4.0 / 3.0 * 3.14159265358979323846 *
           std::pow(double{tree.nodes()[static_cast<std::size_t>(p)].radius}, 3.0);
  return sum;
}

struct Sheared {
  std::vector<Sphere> rest, moved;
  SphereTree rest_tree, refitted, rebuilt;
};

Sheared shear_and_rebuild() {
  Sheared s;
  s.rest = make_packing(0.1, Shape::kBox, 7);
  s.moved = sheared(s.rest, 2.5f);
  auto built = build_sphere_tree(s.rest);
  EXPECT_TRUE(built) << built.error().message;
  s.rest_tree = std::move(built).value();
  s.refitted = s.rest_tree;
  s.refitted.refit(s.moved);
  s.rebuilt = s.refitted;
  const Status rebuilt = rebuild_sphere_tree(s.rebuilt);
  EXPECT_TRUE(rebuilt) << rebuilt.error().message;
  return s;
}

TEST(SphereTreeRebuild, IsAValidRefittableTreeOverTheSameLeavesAsAFreshBuildWouldMake) {
  const Sheared s = shear_and_rebuild();
  ASSERT_TRUE(validate(s.refitted)) << validate(s.refitted).error().message;
  const Status valid = validate(s.rebuilt);
  ASSERT_TRUE(valid) << valid.error().message;
  EXPECT_TRUE(s.rebuilt.refittable());
  // each leaf keeps its index: the leaf spheres are the moved ones, in packing order
  ASSERT_EQ(s.rebuilt.leaf_count(), static_cast<int>(s.moved.size()));
  for (std::size_t i = 0; i < s.moved.size(); ++i) {
    EXPECT_EQ(s.rebuilt.leaves()[i].x, s.moved[i].x);
    EXPECT_EQ(s.rebuilt.leaves()[i].radius, s.moved[i].radius);
  }
  // node for node the tree a fresh build makes over the moved leaves (not the rest topology)
  auto fresh = build_sphere_tree(s.moved);
  ASSERT_TRUE(fresh);
  ASSERT_EQ(s.rebuilt.node_count(), fresh->node_count());
  EXPECT_EQ(s.rebuilt.depth(), fresh->depth());
  int differs_from_rest = 0;
  for (int i = 0; i < fresh->node_count(); ++i) {
    const SphereTreeNode& a = s.rebuilt.nodes()[static_cast<std::size_t>(i)];
    const SphereTreeNode& b = fresh->nodes()[static_cast<std::size_t>(i)];
    ASSERT_TRUE(a.x == b.x && a.y == b.y && a.z == b.z && a.radius == b.radius && a.volume == b.volume &&
                a.first == b.first && a.count == b.count && a.parent == b.parent)
        << "node " << i;
    const SphereTreeNode& r = s.refitted.nodes()[static_cast<std::size_t>(i)];
    if (r.is_leaf() && r.first != a.first) ++differs_from_rest;
  }
  EXPECT_GT(differs_from_rest, s.rebuilt.leaf_count() / 4) << "the rebuild kept the rest grouping";
  // the traversal blocks and densities follow the nodes
  const SphereTree::Blocks got = s.rebuilt.blocks(), want = fresh->blocks();
  ASSERT_EQ(got.size, want.size);
  EXPECT_EQ(got.root, want.root);
  for (std::int32_t k = 0; k < want.size * want.width; ++k) {
    ASSERT_EQ(got.child[k], want.child[k]) << k;
    for (int f = 0; f < 4; ++f) ASSERT_EQ(got.bounds[4 * k + f], want.bounds[4 * k + f]) << k;
  }
  for (int i = 0; i < fresh->node_count(); ++i)
    ASSERT_EQ(s.rebuilt.density()[static_cast<std::size_t>(i)], fresh->density()[static_cast<std::size_t>(i)])
        << i;
}

TEST(SphereTreeRebuild, TightensWhatTheRefitLoosened) {
  const Sheared s = shear_and_rebuild();
  // the kept sums against the node spheres summed here
  for (const SphereTree* t : {&s.rest_tree, &s.refitted, &s.rebuilt})
    EXPECT_NEAR(t->leaf_parent_volume(), inner_volume_by_hand(*t), 1e-9 * inner_volume_by_hand(*t));
  // a shear keeps the volume: the rebuilt tree's node spheres are back near the rest tree's, the
  // refitted ones far above
  const double rest = s.rest_tree.leaf_parent_volume();
  EXPECT_GT(s.refitted.leaf_parent_volume(), 2.0 * rest);
  EXPECT_LT(s.rebuilt.leaf_parent_volume(), 1.25 * rest);
  EXPECT_GT(s.rebuilt.leaf_parent_volume(), 0.75 * rest);
}

// Squashed to half its height (bulging by a quarter each way, its spheres halved with their
// smallest stretch), the box's volume shrinks to 0.78 of rest: the refitted node spheres, over the
// volume, grow looser than at rest; the rebuilt ones come back near the rest ratio.
TEST(SphereTreeRebuild, TightensASquashedPackingOverItsVolume) {
  const std::vector<Sphere> rest = make_packing(0.1, Shape::kBox, 7);
  std::vector<Sphere> squashed = rest;
  for (Sphere& s : squashed) s = {1.25f * s.x, 1.25f * s.y, 0.5f * s.z, 0.5f * s.radius};
  const double volume_ratio = 1.25 * 1.25 * 0.5;
  auto built = build_sphere_tree(rest);
  ASSERT_TRUE(built);
  SphereTree tree = std::move(built).value();
  const double at_rest = inner_volume_by_hand(tree);
  tree.refit(squashed);
  const double refitted = inner_volume_by_hand(tree) / volume_ratio;
  ASSERT_TRUE(rebuild_sphere_tree(tree));
  const double rebuilt = inner_volume_by_hand(tree) / volume_ratio;
  std::printf("squashed, over the volume: refitted %.3f, rebuilt %.3f of rest\n", refitted / at_rest,
              rebuilt / at_rest);
  EXPECT_GT(refitted, 1.3 * at_rest);
  EXPECT_LT(rebuilt, 1.15 * at_rest);
}

// The query over the rebuilt tree finds every overlapping leaf pair a loop over all pairs finds,
// with the same volume, and visits fewer node pairs than over the refitted tree.
TEST(SphereTreeRebuild, QueriesMatchBruteForceAndVisitFewerNodes) {
  const Sheared s = shear_and_rebuild();
  const std::vector<Sphere> probe = make_packing(0.1, Shape::kBall, 11);
  auto probe_tree = build_sphere_tree(probe);
  ASSERT_TRUE(probe_tree);
  VolumeQuery query;
  std::int64_t visited_rebuilt = 0, visited_refitted = 0;
  const double probe_scale = 0.4;  // the ball shrunk to 0.4 across, pressed into the sheared box
  std::vector<Sphere> small(probe.size());
  for (std::size_t i = 0; i < probe.size(); ++i)
    small[i] = {probe[i].x * static_cast<float>(probe_scale), probe[i].y * static_cast<float>(probe_scale),
                probe[i].z * static_cast<float>(probe_scale),
                probe[i].radius * static_cast<float>(probe_scale)};
  auto small_tree = build_sphere_tree(small);
  ASSERT_TRUE(small_tree);
  const Vec3 places[] = {
      {0.0, 0.0, 0.0}, {1.0, 0.1, 0.4}, {-1.0, -0.3, -0.4}, {0.5, 0.5, 0.2}, {-2.0, 0.0, -0.3}};
  for (const Vec3& at : places) {
    const Pose pose{Quat{}, at};
    const testing::BruteVolume ref = brute_volume(s.moved, small, pose);
    ASSERT_GT(ref.volume, 0.0) << "the probe misses the box at " << at.x;
    const VolumeQueryResult r = query.run(s.rebuilt, *small_tree, pose);
    EXPECT_NEAR(r.total_volume, ref.volume, 1e-4 * ref.volume);
    std::set<std::pair<int, int>> got;
    for (const PairOverlap& p : query.pairs()) got.emplace(p.leaf_a, p.leaf_b);
    const std::set<std::pair<int, int>> want(ref.pairs.begin(), ref.pairs.end());
    EXPECT_EQ(got, want) << "at x " << at.x;
    visited_rebuilt += r.stats.node_pairs_visited;
    const VolumeQueryResult loose = query.run(s.refitted, *small_tree, pose);
    EXPECT_NEAR(loose.total_volume, ref.volume, 1e-4 * ref.volume);
    visited_refitted += loose.stats.node_pairs_visited;
  }
  EXPECT_LT(static_cast<double>(visited_rebuilt), 0.8 * static_cast<double>(visited_refitted));
}

TEST(SphereTreeRebuild, KeepsTheTreesStorageAndRefitsAfterwards) {
  Sheared s = shear_and_rebuild();
  const SphereTreeNode* nodes = s.rebuilt.nodes().data();
  const Sphere* leaves = s.rebuilt.leaves().data();
  s.rebuilt.refit(s.rest);  // back to rest, on the sheared grouping
  ASSERT_TRUE(rebuild_sphere_tree(s.rebuilt));
  EXPECT_EQ(s.rebuilt.nodes().data(), nodes);
  EXPECT_EQ(s.rebuilt.leaves().data(), leaves);
  EXPECT_TRUE(validate(s.rebuilt)) << validate(s.rebuilt).error().message;
  s.rebuilt.refit(sheared(s.rest, -1.0f));
  EXPECT_TRUE(validate(s.rebuilt)) << validate(s.rebuilt).error().message;
}

TEST(SphereTreeRebuild, FailsOnABadLeafAndLeavesTheTreeAsItWas) {
  Sheared s = shear_and_rebuild();
  std::vector<Sphere> bad = s.moved;
  bad[5].radius = 0.f;  // a sphere squeezed to nothing
  s.refitted.refit(bad);
  const std::vector<SphereTreeNode> before(s.refitted.nodes().begin(), s.refitted.nodes().end());
  const Status rebuilt = rebuild_sphere_tree(s.refitted);
  ASSERT_FALSE(rebuilt);
  EXPECT_NE(rebuilt.error().message.find("leaf sphere 5"), std::string::npos) << rebuilt.error().message;
  ASSERT_EQ(s.refitted.node_count(), static_cast<int>(before.size()));
  for (std::size_t i = 0; i < before.size(); ++i) EXPECT_EQ(s.refitted.nodes()[i].first, before[i].first);
  EXPECT_FALSE(rebuild_sphere_tree(s.rebuilt, {.arity = 1}));
}

}  // namespace
}  // namespace uh::collette
