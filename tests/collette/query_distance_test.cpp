#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "test_paths.hpp"
#include "tree_test_support.hpp"
#include "uh/collette/distance_query.hpp"
#include "uh/collette/mesh_import.hpp"
#include "uh/collette/mesh_inside.hpp"
#include "uh/collette/sphere_packing.hpp"
#include "uh/collette/sphere_tree_builder.hpp"

namespace uh::collette {
namespace {

using testing::make_packing;
using testing::Shape;

TEST(DistanceQuery, MatchesBruteForceOverLeaves) {
  const auto la = make_packing(0.15, Shape::kBall, 71);
  const auto lb = make_packing(0.12, Shape::kRod, 72);
  const auto ta = build_sphere_tree(la);
  const auto tb = build_sphere_tree(lb);
  ASSERT_TRUE(ta && tb);
  DistanceQuery cold({.warm_start = false});
  DistanceQuery warm;
  core::SplitMix64 rng{9};
  int apart = 0, touching = 0;
  for (int k = 0; k < 60; ++k) {
    const Pose pose = testing::random_pose(rng, 2.2);
    const double ref = testing::brute_gap(la, lb, pose);
    for (DistanceQuery* q : {&cold, &warm}) {
      const DistanceResult& r = q->run(*ta, *tb, pose);
      if (ref <= 0.0) {
        EXPECT_TRUE(r.overlapping) << "pose " << k;
        EXPECT_EQ(r.distance, 0.0);
        continue;
      }
      EXPECT_FALSE(r.overlapping);
      EXPECT_NEAR(r.distance, ref, 1e-5 * (1.0 + ref)) << "pose " << k;
      // the closest points lie on the reported spheres and are `distance` apart
      EXPECT_NEAR(norm(r.point_b - r.point_a), r.distance, 1e-4 * (1.0 + ref));
      const Sphere& sa = la[static_cast<std::size_t>(r.leaf_a)];
      EXPECT_NEAR(norm(r.point_a - testing::centre(sa)), static_cast<double>(sa.radius), 1e-5);
    }
    (ref > 0.0 ? apart : touching) += 1;
  }
  EXPECT_GT(apart, 10);
  EXPECT_GT(touching, 5);
}

TEST(DistanceQuery, WarmStartKeepsTheAnswerAndSavesWork) {
  const auto la = make_packing(0.08, Shape::kBall, 73);
  const auto ta = build_sphere_tree(la);
  ASSERT_TRUE(ta);
  DistanceQuery cold({.warm_start = false});
  DistanceQuery warm;
  std::int64_t cold_work = 0, warm_work = 0;
  for (int k = 0; k < 50; ++k) {
    // a slow approach along x with a turn: coherent from frame to frame
    const Pose pose{quat_from_axis_angle({0, 1, 0}, 0.01 * k), {2.6 - 0.01 * k, 0.05, 0.0}};
    const DistanceResult c = cold.run(*ta, *ta, pose);
    const DistanceResult& w = warm.run(*ta, *ta, pose);
    EXPECT_DOUBLE_EQ(c.distance, w.distance) << "frame " << k;
    cold_work += c.stats.node_pairs_visited;
    if (k > 0) warm_work += w.stats.node_pairs_visited;
    else cold_work -= c.stats.node_pairs_visited;
  }
  EXPECT_LE(warm_work, cold_work);
}

TEST(DistanceQuery, UpperBoundOfTheShapeDistance) {
  // the leaves fill balls of radius 1 (up to the packing gap): the sphere-set distance is never
  // below the distance of the balls, and above it by at most the two gaps
  const auto la = make_packing(0.1, Shape::kBall, 74);
  const auto ta = build_sphere_tree(la);
  ASSERT_TRUE(ta);
  double gap = 0.0;  // largest distance from the unit sphere surface to the leaves, sampled
  {
    std::mt19937 rng(3);
    std::normal_distribution<double> g;
    for (int s = 0; s < 2000; ++s) {
      const Vec3 p = normalized(Vec3{g(rng), g(rng), g(rng)});
      double best = 1e300;
      for (const Sphere& l : la) best = std::min(best, norm(p - testing::centre(l)) - static_cast<double>(l.radius));
      gap = std::max(gap, best);
    }
  }
  double outer = 0.0;  // leaves may poke out of the unit ball by at most this
  for (const Sphere& l : la) outer = std::max(outer, norm(testing::centre(l)) + static_cast<double>(l.radius) - 1.0);
  DistanceQuery q;
  for (double sep : {0.05, 0.3, 1.0, 4.0}) {
    const Pose pose{quat_from_axis_angle({1, 1, 0}, 0.4), {2.0 + sep, 0.0, 0.0}};
    const DistanceResult& r = q.run(*ta, *ta, pose);
    EXPECT_GE(r.distance, sep - 2.0 * outer - 1e-6);
    EXPECT_LE(r.distance, sep + 2.0 * gap + 1e-6);
  }
}

}  // namespace
}  // namespace uh::collette

namespace uh::collette {
namespace {

TEST(DistanceQuery, BoundsTheBunnyMeshDistance) {
  auto mesh = load_mesh(std::string(UH_TEST_DATA_DIR) + "/meshes/bunny_npm_3674.obj");
  ASSERT_TRUE(mesh) << mesh.error().message;
  PackingOptions options;
  options.target_sphere_count = 1000;
  const auto packing = pack_spheres(*mesh, options);
  ASSERT_TRUE(packing) << packing.error().message;
  const auto tree = build_sphere_tree(packing->spheres);
  ASSERT_TRUE(tree);
  const MeshInside surface(*mesh);
  double max_edge = 0.0;
  for (const auto& t : mesh->triangles)
    for (int e = 0; e < 3; ++e)
      max_edge = std::max(max_edge, norm(mesh->vertices[static_cast<std::size_t>(t[static_cast<std::size_t>(e)])] -
                                         mesh->vertices[static_cast<std::size_t>(t[static_cast<std::size_t>((e + 1) % 3)])]));
  const Aabb box = mesh_bounds(*mesh);
  const Vec3 size = box.max - box.min;
  const Quat rot = quat_from_axis_angle({0, 1, 0}, 0.5);
  DistanceQuery q;
  int apart = 0;
  for (double shift : {1.0, 1.1, 1.3, 2.0}) {
    const Pose b_in_a{rot, {shift * size.x, 0.05 * size.y, 0.0}};
    // brute force over A's vertices against B's triangles (exact point-to-mesh distance); the
    // mesh distance is at most this and, the distance to a mesh being 1-Lipschitz, at least this
    // minus the longest edge
    const Pose a_in_b = inverse(b_in_a);
    double vertex_distance = 1e300;
    for (const Vec3& v : mesh->vertices) vertex_distance = std::min(vertex_distance, surface.distance(transform_point(a_in_b, v)));
    for (const Vec3& v : mesh->vertices) vertex_distance = std::min(vertex_distance, surface.distance(transform_point(b_in_a, v)));
    const DistanceResult& r = q.run(*tree, *tree, b_in_a);
    if (vertex_distance > max_edge) {
      EXPECT_FALSE(r.overlapping) << "shift " << shift;
      ++apart;
    }
    // never below the mesh distance (the spheres are inside the meshes) ...
    EXPECT_GE(r.distance, vertex_distance - max_edge - 1e-9) << "shift " << shift;
    // ... and above it by at most the two packing gaps
    EXPECT_LE(r.distance, vertex_distance + 2.0 * packing->report.max_gap + 1e-9) << "shift " << shift;
  }
  EXPECT_GE(apart, 2) << "the poses must separate the meshes: the test would prove little";
}

}  // namespace
}  // namespace uh::collette
