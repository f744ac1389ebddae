#include <gtest/gtest.h>

#include <cstring>
#include <limits>

#include "mesh_test_support.hpp"
#include "test_paths.hpp"
#include "uh/collette/mesh_import.hpp"
#include "uh/collette/sphere_packing.hpp"

namespace uh::collette {
namespace {

Vec3 centre(const Sphere& s) {
  return {static_cast<double>(s.x), static_cast<double>(s.y), static_cast<double>(s.z)};
}

TriangleMesh bunny() {
  auto r = load_mesh(std::filesystem::path(UH_TEST_DATA_DIR) / "meshes" / "bunny_npm_3674.obj");
  EXPECT_TRUE(r) << r.error().message;
  return std::move(r).value();
}

TriangleMesh validated(TriangleMesh m) {
  auto r = validate_mesh(std::move(m));
  EXPECT_TRUE(r) << r.error().message;
  return std::move(r).value();
}

// The packing's promises, checked by brute force: every centre inside (reference winding
// number), every sphere short of every triangle, no two spheres overlapping, report consistent.
void expect_valid_packing(const TriangleMesh& m, const SpherePacking& p) {
  ASSERT_EQ(p.report.sphere_count, static_cast<std::int64_t>(p.spheres.size()));
  double volume = 0.0;
  for (const Sphere& s : p.spheres) {
    ASSERT_GT(s.radius, 0.f);
    const Vec3 c = centre(s);
    ASSERT_GT(test::brute_winding(m, c), 0.5) << "centre outside the mesh";
    ASSERT_GT(test::brute_distance(m, c), static_cast<double>(s.radius)) << "sphere crosses the surface";
    volume += 4.0 / 3.0 * kPi * std::pow(static_cast<double>(s.radius), 3);
  }
  for (std::size_t i = 0; i < p.spheres.size(); ++i) {
    for (std::size_t j = i + 1; j < p.spheres.size(); ++j) {
      const double d = norm(centre(p.spheres[i]) - centre(p.spheres[j]));
      ASSERT_GE(d, static_cast<double>(p.spheres[i].radius) + static_cast<double>(p.spheres[j].radius))
          << "spheres " << i << " and " << j << " overlap";
    }
  }
  EXPECT_NEAR(p.report.sphere_volume, volume, 1e-9 * volume);
  EXPECT_NEAR(p.report.mesh_volume, mesh_volume(m), 1e-12 * mesh_volume(m));
  EXPECT_NEAR(p.report.coverage, volume / mesh_volume(m), 1e-9);
  EXPECT_LT(p.report.coverage, 1.0);
  EXPECT_GT(p.report.voxel_size, 0.0);
  EXPECT_GE(p.report.build_seconds, 0.0);
}

TEST(SpherePacking, BunnySpheresInsideAndDisjoint) {
  const TriangleMesh m = bunny();
  const auto p = pack_spheres(m, {.target_sphere_count = 300});
  ASSERT_TRUE(p) << p.error().message;
  EXPECT_EQ(p->spheres.size(), 300u);
  expect_valid_packing(m, *p);
  EXPECT_GT(p->report.coverage, 0.6);
  // greedy: spheres come largest first (refinement can only grow a sphere a little)
  EXPECT_GE(p->spheres.front().radius, p->spheres.back().radius);
}

TEST(SpherePacking, PrimitivesSpheresInsideAndDisjoint) {
  const TriangleMesh cube = validated(test::unit_cube());
  const TriangleMesh ball = validated(test::icosphere(1.5, 3));
  const TriangleMesh ring = validated(test::torus(2.0, 0.6, 48, 24));
  for (const TriangleMesh* m : {&cube, &ball, &ring}) {
    const auto p = pack_spheres(*m, {.target_sphere_count = 200});
    ASSERT_TRUE(p) << p.error().message;
    // the ball is nearly filled by its first sphere; what is left are slivers below voxel size
    if (m != &ball) {
      EXPECT_EQ(p->spheres.size(), 200u) << m->source_name;
    }
    EXPECT_GE(p->spheres.size(), 1u);
    expect_valid_packing(*m, *p);
    EXPECT_GT(p->report.coverage, 0.5) << m->source_name;
  }
}

TEST(SpherePacking, BallIsMostlyOneSphere) {
  const TriangleMesh ball = validated(test::icosphere(1.0, 4));
  const auto p = pack_spheres(ball, {.target_sphere_count = 1});
  ASSERT_TRUE(p) << p.error().message;
  ASSERT_EQ(p->spheres.size(), 1u);
  // the inscribed polyhedron's inradius is about 0.995: the refined sphere should come close
  EXPECT_GT(p->spheres[0].radius, 0.97f);
  EXPECT_LT(norm(centre(p->spheres[0])), 0.03);
}

TEST(SpherePacking, Deterministic) {
  const TriangleMesh m = bunny();
  const PackingOptions options{.target_sphere_count = 400};
  const auto a = pack_spheres(m, options);
  const auto b = pack_spheres(m, options);
  ASSERT_TRUE(a && b);
  ASSERT_EQ(a->spheres.size(), b->spheres.size());
  EXPECT_EQ(std::memcmp(a->spheres.data(), b->spheres.data(), a->spheres.size() * sizeof(Sphere)), 0);
}

TEST(SpherePacking, MoreSpheresCoverMoreAndLeaveSmallerGaps) {
  const TriangleMesh m = bunny();
  const auto few = pack_spheres(m, {.target_sphere_count = 50});
  const auto many = pack_spheres(m, {.target_sphere_count = 1000});
  ASSERT_TRUE(few && many);
  EXPECT_LT(few->report.coverage, many->report.coverage);
  EXPECT_GT(few->report.max_gap, many->report.max_gap);
  EXPECT_GT(many->report.coverage, 0.7);
}

TEST(SpherePacking, ProgressIsMonotoneAndEndsAtOne) {
  const TriangleMesh m = bunny();
  std::vector<double> seen;
  const auto p = pack_spheres(m, {.target_sphere_count = 200, .progress = [&](double f) { seen.push_back(f); }});
  ASSERT_TRUE(p);
  ASSERT_GE(seen.size(), 3u);
  EXPECT_GE(seen.front(), 0.0);
  for (std::size_t i = 1; i < seen.size(); ++i) EXPECT_GE(seen[i], seen[i - 1]);
  EXPECT_EQ(seen.back(), 1.0);
}

TEST(SpherePacking, UnlimitedCountFillsUntilNoVoxelIsFree) {
  const TriangleMesh cube = validated(test::unit_cube());
  const auto p = pack_spheres(cube, {.target_sphere_count = 0, .voxel_size = 0.1});
  ASSERT_TRUE(p) << p.error().message;
  expect_valid_packing(cube, *p);
  EXPECT_GT(p->spheres.size(), 50u);
  EXPECT_GT(p->report.coverage, 0.6);
}

TEST(SpherePacking, OpenMeshIsFilledUsingTheWindingNumber) {
  TriangleMesh cube = test::unit_cube();
  cube.triangles.resize(10);
  cube.source_name = "open cube";
  const auto open = validate_mesh(cube, {.allow_open = true});
  ASSERT_TRUE(open);
  const auto p = pack_spheres(*open, {.target_sphere_count = 100});
  ASSERT_TRUE(p) << p.error().message;
  ASSERT_EQ(p->spheres.size(), 100u);
  for (const Sphere& s : p->spheres) {
    const double r = static_cast<double>(s.radius);
    EXPECT_GT(s.x - s.radius, 0.f);
    EXPECT_LT(static_cast<double>(s.x) + r, 1.0 + 1e-6);  // the missing face is assumed flat
    EXPECT_GT(s.y - s.radius, 0.f);
    EXPECT_LT(static_cast<double>(s.y) + r, 1.0);
    EXPECT_GT(s.z - s.radius, 0.f);
    EXPECT_LT(static_cast<double>(s.z) + r, 1.0);
  }
}

TEST(SpherePacking, FillsTheOverlapOfInterpenetratingShells) {
  TriangleMesh two = test::unit_cube();
  const TriangleMesh second = test::unit_cube();
  for (const Vec3& v : second.vertices) two.vertices.push_back(v + Vec3{0.5, 0.0, 0.0});
  for (const auto& t : second.triangles) two.triangles.push_back({t[0] + 8, t[1] + 8, t[2] + 8});
  const TriangleMesh m = validated(two);
  const auto p = pack_spheres(m, {.target_sphere_count = 300});
  ASSERT_TRUE(p) << p.error().message;
  int in_overlap = 0;
  for (const Sphere& s : p->spheres) {
    ASSERT_GT(test::brute_winding(m, centre(s)), 0.5);
    ASSERT_GT(test::brute_distance(m, centre(s)), static_cast<double>(s.radius));
    in_overlap += (s.x > 0.5f && s.x < 1.0f) ? 1 : 0;
  }
  EXPECT_GT(in_overlap, 10);
}

TEST(SpherePacking, BoundedRadiusIsKeptEverywhere) {
  const TriangleMesh cube = validated(test::unit_cube());
  const auto free = pack_spheres(cube, {.target_sphere_count = 3000});
  const auto bounded = pack_spheres(cube, {.target_sphere_count = 3000, .max_radius = 0.08});
  ASSERT_TRUE(free && bounded) << (free ? bounded.error().message : free.error().message);
  expect_valid_packing(cube, *bounded);
  EXPECT_EQ(bounded->spheres.size(), 3000u);
  for (const Sphere& s : bounded->spheres) ASSERT_LE(s.radius, 0.08f);
  // the bound is reached (the first spheres are as large as allowed, less the safety margin)
  EXPECT_NEAR(static_cast<double>(bounded->spheres.front().radius), 0.08, 1e-3 * 0.08);
  EXPECT_LE(bounded->report.max_radius, 0.08);
  EXPECT_GT(free->report.max_radius, 0.4);
  // many equal spheres fill a cube less than one large one and its gaps, but not much less
  EXPECT_GT(bounded->report.coverage, 0.6);
  EXPECT_LT(bounded->report.coverage, free->report.coverage);
}

TEST(SpherePacking, RejectsBadInput) {
  TriangleMesh empty;
  empty.source_name = "nothing";
  const auto a = pack_spheres(empty);
  ASSERT_FALSE(a);
  EXPECT_NE(a.error().message.find("nothing"), std::string::npos);
  TriangleMesh open = test::unit_cube();
  open.triangles.resize(10);
  open.report.boundary_edges = 4;  // as validation would have found, without allow_open
  EXPECT_FALSE(pack_spheres(open));
  const TriangleMesh cube = validated(test::unit_cube());
  EXPECT_FALSE(pack_spheres(cube, {.voxel_size = 1e-5}));  // 10^15 voxels
  EXPECT_FALSE(pack_spheres(cube, {.voxel_size = -1.0}));
  EXPECT_FALSE(pack_spheres(cube, {.max_radius = -0.1}));
  EXPECT_FALSE(pack_spheres(cube, {.max_radius = std::numeric_limits<double>::quiet_NaN()}));
}

TEST(SpherePacking, MaxGapMatchesBruteForceAtVertices) {
  const TriangleMesh m = bunny();
  const auto p = pack_spheres(m, {.target_sphere_count = 150});
  ASSERT_TRUE(p);
  double ref = 0.0;
  for (const Vec3& v : m.vertices) {
    double d = 1e300;
    for (const Sphere& s : p->spheres) d = std::min(d, norm(v - centre(s)) - static_cast<double>(s.radius));
    ref = std::max(ref, std::max(d, 0.0));
  }
  EXPECT_NEAR(measure_max_gap(m, p->spheres, 0), ref, 1e-9);
  EXPECT_GE(p->report.max_gap, ref - 1e-9);  // more sample points can only find a larger gap
}

}  // namespace
}  // namespace uh::collette
