#pragma once
// Shared by the proxy's tests: packed boxes and the brute-force overlap of two sphere trees.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <utility>

#include "uh/collette/mesh_import.hpp"
#include "uh/collette/sphere_packing.hpp"
#include "uh/collette/sphere_tree_builder.hpp"
#include "uh/core/math.hpp"

namespace uh::controllers::testing {

inline collette::TriangleMesh box_mesh(const Vec3& size) {
  collette::TriangleMesh m;
  m.source_name = "box";
  for (const Vec3& v : std::initializer_list<Vec3>{
           {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}})
    m.vertices.push_back(Vec3{(v.x - 0.5) * size.x, (v.y - 0.5) * size.y, (v.z - 0.5) * size.z});
  m.triangles = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                 {3, 7, 6}, {3, 6, 2}, {0, 4, 7}, {0, 7, 3}, {1, 2, 6}, {1, 6, 5}};
  return m;
}

struct Packed {
  std::shared_ptr<const collette::SphereTree> tree;
  double max_gap = 0.0;  // the packing's largest distance from the mesh surface to its spheres [m]
};

inline Packed pack(const collette::TriangleMesh& mesh, std::int64_t spheres) {
  auto valid = collette::validate_mesh(mesh);
  EXPECT_TRUE(valid) << valid.error().message;
  auto packing = collette::pack_spheres(*valid, {.target_sphere_count = spheres});
  EXPECT_TRUE(packing) << packing.error().message;
  auto tree = collette::build_sphere_tree(packing->spheres);
  EXPECT_TRUE(tree) << tree.error().message;
  return {std::make_shared<const collette::SphereTree>(std::move(tree).value()), packing->report.max_gap};
}

inline Vec3 centre_of(const Sphere& s) {
  return {static_cast<double>(s.x), static_cast<double>(s.y), static_cast<double>(s.z)};
}

// The deepest overlap of any tool sphere with any plate sphere, by brute force [m].
inline double deepest_overlap(const collette::SphereTree& plate, const Pose& world_from_plate,
                              const collette::SphereTree& tool, const Pose& world_from_tool) {
  double deepest = 0.0;
  for (const Sphere& b : tool.leaves()) {
    const Vec3 cb = transform_point(world_from_tool, centre_of(b));
    for (const Sphere& a : plate.leaves()) {
      const Vec3 ca = transform_point(world_from_plate, centre_of(a));
      deepest = std::max(deepest, static_cast<double>(a.radius + b.radius) - norm(cb - ca));
    }
  }
  return deepest;
}

}  // namespace uh::controllers::testing
