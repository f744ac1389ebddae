#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "tree_test_support.hpp"
#include "uh/collette/sphere_tree.hpp"
#include "uh/collette/sphere_tree_builder.hpp"

namespace uh::collette {
namespace {

using testing::make_packing;
using testing::Shape;

TEST(SphereTree, BuildPassesValidateOnManyLeafSets) {
  std::vector<std::vector<Sphere>> sets;
  sets.push_back({{0.f, 0.f, 0.f, 1.f}});
  sets.push_back({{0.f, 0.f, 0.f, 1.f}, {3.f, 0.f, 0.f, 0.5f}});
  sets.push_back(make_packing(0.5, Shape::kBall, 1));
  sets.push_back(make_packing(0.12, Shape::kBall, 2));
  sets.push_back(make_packing(0.1, Shape::kBox, 3));
  sets.push_back(make_packing(0.05, Shape::kRod, 4));
  // identical centres: k-means cannot separate them, the builder must still split
  sets.push_back(std::vector<Sphere>(37, Sphere{1.f, 2.f, 3.f, 0.25f}));
  for (const SphereTreeSplit split : {SphereTreeSplit::kBalanced, SphereTreeSplit::kKMeans}) {
    for (int arity : {2, 4, 8}) {
      for (std::size_t s = 0; s < sets.size(); ++s) {
        const auto tree = build_sphere_tree(sets[s], {.arity = arity, .split = split});
        ASSERT_TRUE(tree) << tree.error().message;
        const Status ok = validate(*tree);
        EXPECT_TRUE(ok) << "set " << s << " arity " << arity << " split " << static_cast<int>(split) << ": "
                        << (ok ? "" : ok.error().message);
        EXPECT_EQ(tree->leaf_count(), static_cast<int>(sets[s].size()));
        EXPECT_LE(tree->node_count(), 2 * tree->leaf_count());
        double volume = 0.0;
        for (const Sphere& l : sets[s])
          volume += 4.0 / 3.0 * kPi * std::pow(static_cast<double>(l.radius), 3);
        EXPECT_NEAR(tree->total_volume(), volume, 1e-5 * volume);
      }
    }
  }
}

// The balanced split: every leaf at the depth that n leaves need at the arity (within one level at
// arity 2, where a node of three leaves has a leaf and a pair), and every inner node as full as
// that allows (a node over m leaves has ceil(m / c) children, c = arity^(levels below it - 1)),
// counted independently of the builder by walking the finished tree.
TEST(SphereTree, BalancedSplitPutsLeavesAtOneDepthInFullNodes) {
  for (const auto& [h, shape, seed] : {std::tuple{0.12, Shape::kBall, 2u}, std::tuple{0.05, Shape::kRod, 4u},
                                       std::tuple{0.1, Shape::kBox, 3u}}) {
    const auto leaves = make_packing(h, shape, seed);
    for (int arity : {2, 3, 4, 8}) {
      SCOPED_TRACE("arity " + std::to_string(arity) + ", " + std::to_string(leaves.size()) + " leaves");
      const auto tree = build_sphere_tree(leaves, {.arity = arity});
      ASSERT_TRUE(tree);
      const std::vector<SphereTreeNode> nodes(tree->nodes().begin(), tree->nodes().end());
      int levels = 1;  // of a tree over all leaves: the smallest L with arity^(L - 1) >= n
      for (double full = 1.0; full < static_cast<double>(leaves.size()); full *= arity) ++levels;
      EXPECT_EQ(tree->depth(), levels);
      std::vector<int> depth(nodes.size(), 0), below(nodes.size(), 0);
      depth[0] = 1;
      for (std::size_t i = 0; i < nodes.size(); ++i)
        for (int c = nodes[i].first; !nodes[i].is_leaf() && c < nodes[i].first + nodes[i].count; ++c)
          depth[static_cast<std::size_t>(c)] = depth[i] + 1;
      for (std::size_t i = nodes.size(); i-- > 0;) {
        if (nodes[i].is_leaf()) {
          below[i] = 1;
          if (arity == 2)
            EXPECT_GE(depth[i], levels - 1) << "leaf node " << i;
          else
            EXPECT_EQ(depth[i], levels) << "leaf node " << i;
        }
        if (nodes[i].parent >= 0) below[static_cast<std::size_t>(nodes[i].parent)] += below[i];
      }
      for (std::size_t i = 0; i < nodes.size(); ++i) {
        if (nodes[i].is_leaf() || arity == 2) continue;
        double capacity = 1.0;  // of a child: the largest power of the arity below the node's leaves
        while (capacity * arity < below[i]) capacity *= arity;
        EXPECT_EQ(nodes[i].count, static_cast<int>(std::ceil(below[i] / capacity))) << "node " << i;
      }
    }
  }
}

TEST(SphereTree, HierarchyIsBalancedAndTight) {
  const auto leaves = make_packing(0.05, Shape::kBall, 7);  // ~33k leaves
  ASSERT_GT(leaves.size(), 10000u);
  const auto tree = build_sphere_tree(leaves, {.arity = 4});
  ASSERT_TRUE(tree);
  // a balanced 4-ary tree over n leaves has about log4(n) levels
  EXPECT_LE(tree->depth(), static_cast<int>(std::ceil(std::log(static_cast<double>(leaves.size())) / std::log(4.0))) + 4);
  // the root of a ball packing is close to the ball (radius 1 plus a leaf radius)
  EXPECT_LT(static_cast<double>(tree->root().radius), 1.05);
}

TEST(SphereTree, BuildIsDeterministic) {
  const auto leaves = make_packing(0.1, Shape::kBox, 11);
  for (const SphereTreeSplit split : {SphereTreeSplit::kBalanced, SphereTreeSplit::kKMeans}) {
    const auto t1 = build_sphere_tree(leaves, {.split = split});
    const auto t2 = build_sphere_tree(leaves, {.split = split});
    ASSERT_TRUE(t1 && t2);
    ASSERT_EQ(t1->node_count(), t2->node_count());
    for (int i = 0; i < t1->node_count(); ++i) {
      const auto& a = t1->nodes()[static_cast<std::size_t>(i)];
      const auto& b = t2->nodes()[static_cast<std::size_t>(i)];
      ASSERT_TRUE(a.x == b.x && a.y == b.y && a.z == b.z && a.radius == b.radius && a.volume == b.volume &&
                  a.first == b.first && a.count == b.count && a.parent == b.parent)
          << "node " << i;
    }
  }
}

TEST(SphereTree, BuildRejectsBadInput) {
  EXPECT_FALSE(build_sphere_tree({}));
  const std::vector<Sphere> bad_radius{{0.f, 0.f, 0.f, 1.f}, {2.f, 0.f, 0.f, 0.f}};
  const auto r = build_sphere_tree(bad_radius);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("leaf sphere 1"), std::string::npos) << r.error().message;
  const std::vector<Sphere> nan_centre{{std::nanf(""), 0.f, 0.f, 1.f}};
  EXPECT_FALSE(build_sphere_tree(nan_centre));
  const std::vector<Sphere> one{{0.f, 0.f, 0.f, 1.f}};
  EXPECT_FALSE(build_sphere_tree(one, {.arity = 1}));
  EXPECT_FALSE(build_sphere_tree(one, {.arity = kMaxSphereTreeArity + 1}));
}

// Rebuilds a tree with one node changed by `edit` and returns validate()'s message ("" if valid).
template <typename Edit>
std::string validate_edited(const SphereTree& t, Edit edit) {
  std::vector<SphereTreeNode> nodes(t.nodes().begin(), t.nodes().end());
  std::vector<Sphere> leaves(t.leaves().begin(), t.leaves().end());
  int depth = t.depth();
  edit(nodes, leaves, depth);
  const Status s = validate(SphereTree(nodes, leaves, depth, t.arity()));
  return s ? std::string() : s.error().message;
}

TEST(SphereTree, ValidateCatchesBrokenTrees) {
  const auto built = build_sphere_tree(make_packing(0.25, Shape::kBall, 5));
  ASSERT_TRUE(built);
  const SphereTree& t = *built;
  ASSERT_TRUE(validate(t));
  using Nodes = std::vector<SphereTreeNode>;
  using Leaves = std::vector<Sphere>;
  // first inner node below the root, and a leaf node
  int inner = -1, leaf = -1;
  for (int i = 1; i < t.node_count(); ++i) {
    if (inner < 0 && !t.nodes()[static_cast<std::size_t>(i)].is_leaf()) inner = i;
    if (leaf < 0 && t.nodes()[static_cast<std::size_t>(i)].is_leaf()) leaf = i;
  }
  ASSERT_GT(inner, 0);
  ASSERT_GT(leaf, 0);
  const auto ui = static_cast<std::size_t>(inner);
  const auto ul = static_cast<std::size_t>(leaf);
  EXPECT_EQ(validate_edited(t, [](Nodes&, Leaves&, int&) {}), "");
  EXPECT_NE(validate_edited(t, [&](Nodes& n, Leaves&, int&) { n[ui].first = static_cast<int>(n.size()); }).find("outside the node array"),
            std::string::npos);
  EXPECT_NE(validate_edited(t, [&](Nodes& n, Leaves&, int&) { n[ui].count = kMaxSphereTreeArity + 1; }).find("child count"),
            std::string::npos);
  EXPECT_NE(validate_edited(t, [&](Nodes& n, Leaves&, int&) { n[0].radius *= 0.5f; }).find("does not enclose"), std::string::npos);
  EXPECT_NE(validate_edited(t, [&](Nodes& n, Leaves&, int&) { n[ui].x += n[ui].radius; }).find("does not enclose"),
            std::string::npos);
  EXPECT_NE(validate_edited(t, [&](Nodes& n, Leaves&, int&) { n[ui].volume *= 1.5f; }).find("not the sum"), std::string::npos);
  EXPECT_NE(validate_edited(t, [&](Nodes& n, Leaves&, int&) { n[ul].volume *= 1.5f; }).find("volume"),
            std::string::npos);
  EXPECT_NE(validate_edited(t, [&](Nodes& n, Leaves&, int&) { n[ui].x = std::nanf(""); }).find("non-finite"), std::string::npos);
  EXPECT_NE(validate_edited(t, [&](Nodes& n, Leaves& l, int&) { n[ul].first = (n[ul].first + 1) % static_cast<int>(l.size()); }).find("leaf"),
            std::string::npos);
  EXPECT_NE(validate_edited(t, [&](Nodes&, Leaves& l, int&) { l[0].x += 1.f; }).find("differs from leaf sphere"), std::string::npos);
  EXPECT_NE(validate_edited(t, [&](Nodes&, Leaves&, int& d) { d += 1; }).find("depth"), std::string::npos);
  EXPECT_NE(validate_edited(t, [&](Nodes&, Leaves& l, int&) { l.push_back({0.f, 0.f, 0.f, 0.1f}); }).find("leaf nodes for"),
            std::string::npos);
  // a cycle: an inner node whose children are the root's children, parent links forged to match
  EXPECT_FALSE(validate_edited(t, [&](Nodes& n, Leaves&, int&) {
                 n[ui].first = n[0].first;
                 n[ui].count = n[0].count;
               }).empty());
  // a cycle that also forges the parent links back to the inner node
  EXPECT_FALSE(validate_edited(t, [&](Nodes& n, Leaves&, int&) {
                 n[ui].first = n[0].first;
                 n[ui].count = n[0].count;
                 for (int c = n[0].first; c < n[0].first + n[0].count; ++c) n[static_cast<std::size_t>(c)].parent = inner;
                 n[0].first = inner;
                 n[0].count = 1;
               }).empty());
  EXPECT_FALSE(validate(SphereTree{}));
}

}  // namespace
}  // namespace uh::collette
