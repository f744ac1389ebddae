#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <random>

#include "mesh_test_support.hpp"
#include "test_paths.hpp"
#include "uh/collette/mesh_import.hpp"
#include "uh/collette/mesh_inside.hpp"

namespace uh::collette {
namespace {

TriangleMesh bunny() {
  auto r = load_mesh(std::filesystem::path(UH_TEST_DATA_DIR) / "meshes" / "bunny_npm_3674.obj");
  EXPECT_TRUE(r) << r.error().message;
  return std::move(r).value();
}

std::vector<Vec3> random_points(const Aabb& box, int n, unsigned seed) {
  std::mt19937 rng(seed);
  const Vec3 pad = (box.max - box.min) * 0.1;
  std::uniform_real_distribution<double> ux(box.min.x - pad.x, box.max.x + pad.x);
  std::uniform_real_distribution<double> uy(box.min.y - pad.y, box.max.y + pad.y);
  std::uniform_real_distribution<double> uz(box.min.z - pad.z, box.max.z + pad.z);
  std::vector<Vec3> p;
  for (int i = 0; i < n; ++i) p.push_back({ux(rng), uy(rng), uz(rng)});
  return p;
}

TEST(MeshInside, ContainsMatchesBruteForceWindingOnBunny) {
  const TriangleMesh m = bunny();
  const MeshInside inside(m);
  int n_inside = 0;
  for (const Vec3& p : random_points(mesh_bounds(m), 400, 7)) {
    const double w = test::brute_winding(m, p);
    ASSERT_TRUE(std::abs(w) < 1e-6 || std::abs(w - 1.0) < 1e-6) << "reference winding " << w;
    EXPECT_EQ(inside.contains(p), w > 0.5) << p.x << ' ' << p.y << ' ' << p.z;
    EXPECT_NEAR(inside.winding_number(p), w, 1e-9);
    n_inside += w > 0.5 ? 1 : 0;
  }
  EXPECT_GT(n_inside, 20);  // the sample must exercise both answers
  EXPECT_LT(n_inside, 380);
}

TEST(MeshInside, GrazingRaysOnAxisAlignedCube) {
  // points level with the cube's edges and vertices: single-ray parity gets these wrong
  const auto cube = validate_mesh(test::unit_cube());
  ASSERT_TRUE(cube);
  const MeshInside inside(*cube);
  for (double a : {0.0, 0.25, 0.5, 0.75, 1.0}) {
    for (double b : {0.0, 0.25, 0.5, 0.75, 1.0}) {
      if (a > 0.0 && a < 1.0 && b > 0.0 && b < 1.0) {
        EXPECT_TRUE(inside.contains(Vec3{0.5, a, b}));
        EXPECT_TRUE(inside.contains(Vec3{a, b, 0.5}));
      }
      EXPECT_FALSE(inside.contains(Vec3{-0.5, a, b}));
      EXPECT_FALSE(inside.contains(Vec3{1.5, a, b}));
      EXPECT_FALSE(inside.contains(Vec3{a, b, 2.0}));
    }
  }
  EXPECT_TRUE(inside.contains({1e-6, 1e-6, 1e-6}));
  EXPECT_FALSE(inside.contains({-1e-6, 0.5, 0.5}));
}

TEST(MeshInside, DistanceMatchesBruteForce) {
  const TriangleMesh m = bunny();
  const MeshInside inside(m);
  for (const Vec3& p : random_points(mesh_bounds(m), 300, 11)) {
    const double ref = test::brute_distance(m, p);
    EXPECT_NEAR(inside.distance(p), ref, 1e-9 * (1.0 + ref));
    EXPECT_NEAR(norm(inside.closest_point(p) - p), ref, 1e-9 * (1.0 + ref));
    EXPECT_NEAR(std::abs(inside.signed_distance(p)), ref, 1e-9 * (1.0 + ref));
  }
}

// faces_below keeps the faces a point lies squarely above, nearest first. The reference measures
// every triangle another way: p lies squarely above a face when its distance to the triangle (the
// segment-and-plane formula of the test support) is its height above the triangle's plane.
TEST(MeshInside, FacesBelowMatchesEveryTriangleMeasuredByBruteForce) {
  std::size_t with_turned = 0;  // points above faces turned apart (the bunny's creases; the torus has none)
  for (const TriangleMesh& m : {bunny(), test::torus(1.0, 0.3, 48, 24)}) {
    const MeshInside inside(m);
    const Aabb box = mesh_bounds(m);
    const double reach = 0.05 * norm(box.max - box.min);
    std::size_t compared = 0, with_two = 0;
    for (const Vec3& p : random_points(box, 1000, 5)) {
      std::vector<double> heights;
      for (const auto& t : m.triangles) {
        const Vec3& a = m.vertices[static_cast<std::size_t>(t[0])];
        const Vec3& b = m.vertices[static_cast<std::size_t>(t[1])];
        const Vec3& c = m.vertices[static_cast<std::size_t>(t[2])];
        const double height = dot(p - a, normalized(cross(b - a, c - a)));
        const double distance = test::triangle_distance(p, a, b, c);
        if (height >= 0.0 && height <= reach && std::abs(distance - height) <= 1e-12 * (1.0 + reach))
          heights.push_back(height);
      }
      std::sort(heights.begin(), heights.end());
      std::array<SurfacePoint, 4> out{};
      const std::size_t found = inside.faces_below(p, reach, out);
      ASSERT_EQ(found, std::min(heights.size(), out.size())) << p.x << " " << p.y << " " << p.z;
      for (std::size_t i = 0; i < found; ++i) {
        EXPECT_NEAR(out[i].distance, heights[i], 1e-12 * (1.0 + reach));
        EXPECT_NEAR(norm(p - out[i].point), heights[i], 1e-12 * (1.0 + reach));
        EXPECT_NEAR(dot(p - out[i].point, out[i].face_normal), heights[i], 1e-12 * (1.0 + reach));
      }
      compared += found;
      with_two += found >= 2 ? 1 : 0;
      if (found == 0) continue;
      // turned more than 15 deg from the nearest face's normal: the BVH's normal cones prune, the
      // reference filters every face
      const Vec3 from = out[0].face_normal;
      const double turn = 15.0 * kPi / 180.0;
      std::vector<double> turned;
      for (const auto& t : m.triangles) {
        const Vec3& a = m.vertices[static_cast<std::size_t>(t[0])];
        const Vec3& b = m.vertices[static_cast<std::size_t>(t[1])];
        const Vec3& c = m.vertices[static_cast<std::size_t>(t[2])];
        const Vec3 n = normalized(cross(b - a, c - a));
        const double height = dot(p - a, n);
        if (height >= 0.0 && height <= reach && std::abs(test::triangle_distance(p, a, b, c) - height) <= 1e-12 * (1.0 + reach) &&
            std::acos(std::clamp(dot(n, from), -1.0, 1.0)) > turn)
          turned.push_back(height);
      }
      std::sort(turned.begin(), turned.end());
      const std::size_t turned_found = inside.faces_below(p, reach, out, from, turn);
      ASSERT_EQ(turned_found, std::min(turned.size(), out.size())) << p.x << " " << p.y << " " << p.z;
      for (std::size_t i = 0; i < turned_found; ++i) EXPECT_NEAR(out[i].distance, turned[i], 1e-12 * (1.0 + reach));
      with_turned += turned_found > 0 ? 1 : 0;
    }
    EXPECT_GT(compared, 100u) << m.source_name;  // enough points near the surface to mean something
    EXPECT_GT(with_two, 0u) << m.source_name;    // and some in a concave part, above two faces
  }
  EXPECT_GT(with_turned, 0u);
}

TEST(MeshInside, OpenMeshUsesTheWindingNumber) {
  TriangleMesh cube = test::unit_cube();
  cube.triangles.resize(10);  // no +x face
  cube.source_name = "open";
  const auto open = validate_mesh(cube, {.allow_open = true});
  ASSERT_TRUE(open) << open.error().message;
  const MeshInside inside(*open);
  // the missing face subtends 1/6 of the sphere of directions at the centre
  EXPECT_NEAR(inside.winding_number({0.5, 0.5, 0.5}), 5.0 / 6.0, 1e-12);
  EXPECT_TRUE(inside.contains({0.5, 0.5, 0.5}));
  EXPECT_TRUE(inside.contains({0.2, 0.3, 0.7}));
  EXPECT_FALSE(inside.contains({-0.5, 0.5, 0.5}));
  EXPECT_FALSE(inside.contains({1.5, 0.5, 0.5}));
}

}  // namespace
}  // namespace uh::collette

namespace uh::collette {
namespace {

TEST(MeshInside, OverlapOfInterpenetratingShellsIsInside) {
  // two closed cubes sharing the slab 0.5 < x < 1: winding number 2 there, which parity calls outside
  TriangleMesh two = test::unit_cube();
  const TriangleMesh second = test::unit_cube();
  for (const Vec3& v : second.vertices) two.vertices.push_back(v + Vec3{0.5, 0.0, 0.0});
  for (const auto& t : second.triangles) two.triangles.push_back({t[0] + 8, t[1] + 8, t[2] + 8});
  two.source_name = "two cubes";
  const auto m = validate_mesh(two);
  ASSERT_TRUE(m) << m.error().message;
  EXPECT_EQ(m->report.components, 2);
  const MeshInside inside(*m);
  EXPECT_NEAR(test::brute_winding(*m, {0.75, 0.3, 0.6}), 2.0, 1e-9);
  EXPECT_TRUE(inside.contains({0.75, 0.3, 0.6}));
  EXPECT_TRUE(inside.contains({0.25, 0.3, 0.6}));
  EXPECT_TRUE(inside.contains({1.25, 0.3, 0.6}));
  EXPECT_FALSE(inside.contains({1.75, 0.3, 0.6}));
}

}  // namespace
}  // namespace uh::collette
