// Accuracy of the sphere-packing volume query against the true mesh intersection volume, on the
// committed 3,674-triangle bunny: the true volume (and its gradient) by stratified point counting
// with MeshInside, the packing's by VolumeQuery.

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "test_paths.hpp"
#include "uh/collette/mesh_import.hpp"
#include "uh/collette/mesh_inside.hpp"
#include "uh/collette/sphere_packing.hpp"
#include "uh/collette/sphere_tree_builder.hpp"
#include "uh/collette/volume_query.hpp"

namespace uh::collette {
namespace {

TEST(VolumeQuery, MatchesTrueMeshIntersectionOnBunny) {
  auto mesh = load_mesh(std::string(UH_TEST_DATA_DIR) + "/meshes/bunny_npm_3674.obj");
  ASSERT_TRUE(mesh) << mesh.error().message;
  PackingOptions packing_options;
  packing_options.target_sphere_count = 4000;
  const auto packing = pack_spheres(*mesh, packing_options);
  ASSERT_TRUE(packing) << packing.error().message;
  const auto tree = build_sphere_tree(packing->spheres);
  ASSERT_TRUE(tree);
  const double coverage = packing->report.coverage;
  ASSERT_GT(coverage, 0.7);

  // stratified samples of A's box (one jittered point per cell), kept when inside A
  const MeshInside inside(*mesh);
  const Aabb box = mesh_bounds(*mesh);
  const Vec3 size = box.max - box.min;
  constexpr int kCells = 32;
  const double cell_volume = size.x * size.y * size.z / (kCells * kCells * kCells);
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Vec3> in_a;
  for (int i = 0; i < kCells; ++i)
    for (int j = 0; j < kCells; ++j)
      for (int k = 0; k < kCells; ++k) {
        const Vec3 p{box.min.x + (i + u(rng)) / kCells * size.x, box.min.y + (j + u(rng)) / kCells * size.y,
                     box.min.z + (k + u(rng)) / kCells * size.z};
        if (inside.contains(p)) in_a.push_back(p);
      }
  // sampled volume of A agrees with the mesh volume: the counting is sound
  EXPECT_NEAR(static_cast<double>(in_a.size()) * cell_volume, mesh_volume(*mesh), 0.02 * mesh_volume(*mesh));

  auto true_volume = [&](const Pose& b_in_a) {
    const Pose a_to_b = inverse(b_in_a);
    std::size_t n = 0;
    for (const Vec3& p : in_a) n += inside.contains(transform_point(a_to_b, p)) ? 1u : 0u;
    return static_cast<double>(n) * cell_volume;
  };

  const Vec3 c = 0.5 * (box.min + box.max);
  const Quat rot = quat_from_axis_angle({0, 1, 0}, 30.0 * kPi / 180.0);
  const Quat tilt = quat_from_axis_angle({1, 0, 1}, 20.0 * kPi / 180.0);
  struct Case {
    Quat r;
    Vec3 shift;
  };
  const Case cases[] = {{rot, {0.45 * size.x, 0.0, 0.0}}, {tilt * rot, {0.3 * size.x, 0.15 * size.y, 0.1 * size.z}}};
  VolumeQuery query({.collect_pairs = false});
  for (const Case& k : cases) {
    const Pose b_in_a{k.r, c + k.shift - rotate(k.r, c)};
    const double v_true = true_volume(b_in_a);
    const VolumeQueryResult r = query.run(*tree, *tree, b_in_a);
    ASSERT_GT(v_true, 0.05 * mesh_volume(*mesh)) << "the pose must overlap deeply";
    // the packings lie inside the meshes, so their intersection is smaller; with coverage c each,
    // about c^2 of the true volume is found in deep overlap
    const double ratio = r.total_volume / v_true;
    EXPECT_LT(ratio, 1.03) << "true " << v_true << " packing " << r.total_volume;
    EXPECT_GT(ratio, 0.8 * coverage * coverage) << "true " << v_true << " packing " << r.total_volume;
    // the restoring direction follows the true volume gradient w.r.t. B's translation: moving B
    // along it reduces the overlap fastest
    const double h = 0.03 * size.x;
    Vec3 grad;
    for (int axis = 0; axis < 3; ++axis) {
      Vec3 d{};
      (axis == 0 ? d.x : axis == 1 ? d.y : d.z) = h;
      const double plus = true_volume({b_in_a.rotation, b_in_a.position + d});
      const double minus = true_volume({b_in_a.rotation, b_in_a.position - d});
      (axis == 0 ? grad.x : axis == 1 ? grad.y : grad.z) = (plus - minus) / (2.0 * h);
    }
    const double cosine = dot(r.restoring_direction, normalized(-grad));
    EXPECT_GT(cosine, std::cos(15.0 * kPi / 180.0))
        << "angle " << std::acos(std::min(1.0, cosine)) * 180.0 / kPi << " deg, gradient " << grad.x << " " << grad.y << " "
        << grad.z;
    // the exact gradient of the packing volume follows it more closely
    const double gradient_cosine = dot(normalized(-r.volume_gradient), normalized(-grad));
    EXPECT_GT(gradient_cosine, std::cos(8.0 * kPi / 180.0))
        << "angle " << std::acos(std::min(1.0, gradient_cosine)) * 180.0 / kPi << " deg";
  }
}

// A packing queried against itself, B shifted by 0 to 1e-3 of the object's size: every sphere
// overlaps its own copy almost completely. The overlap can never exceed the spheres' volume and
// must fall off continuously (|dV/dt| <= sum of pi r^2 of the spheres). The textbook lens formula
// cancelled here in float: at a shift of 1e-6 of the size it returned more volume than the
// packing holds, at 1e-7 about half.
TEST(VolumeQuery, PackingAgainstItselfNeverExceedsItsSphereVolumeAndIsContinuous) {
  auto mesh = load_mesh(std::string(UH_TEST_DATA_DIR) + "/meshes/bunny_npm_3674.obj");
  ASSERT_TRUE(mesh) << mesh.error().message;
  PackingOptions packing_options;
  packing_options.target_sphere_count = 2000;
  const auto packing = pack_spheres(*mesh, packing_options);
  ASSERT_TRUE(packing) << packing.error().message;
  const auto tree = build_sphere_tree(packing->spheres);
  ASSERT_TRUE(tree);
  double sphere_volume = 0.0, disk_areas = 0.0;
  for (const Sphere& s : tree->leaves()) {
    const double r = static_cast<double>(s.radius);
    sphere_volume += 4.0 / 3.0 * kPi * r * r * r;
    disk_areas += kPi * r * r;
  }
  const Aabb box = mesh_bounds(*mesh);
  const double size = norm(box.max - box.min);
  const Vec3 direction = normalized(Vec3{1.0, 0.37, -0.21});
  // rounding of float pair volumes summed in double: a few ulps of float of the total
  const double rounding = 1e-6 * sphere_volume;
  VolumeQuery query({.collect_pairs = false});
  std::vector<double> shifts{0.0};
  for (int i = 0; i <= 60; ++i) shifts.push_back(std::pow(10.0, -9.0 + i / 10.0) * size);
  double previous = -1.0, previous_shift = 0.0;
  for (const double t : shifts) {
    const double v = query.run(*tree, *tree, Pose{{}, direction * t}).total_volume;
    EXPECT_LE(v, sphere_volume + rounding) << "shift " << t / size << " of the size";
    if (previous >= 0.0) {
      // falls with the shift, at most at the rate of all the spheres' disks
      EXPECT_LE(v, previous + rounding) << "shift " << t / size << " of the size";
      EXPECT_GE(v, previous - disk_areas * (t - previous_shift) - rounding)
          << "shift " << t / size << " of the size";
    } else {
      EXPECT_NEAR(v, sphere_volume, rounding) << "unshifted, every sphere overlaps its own copy exactly";
    }
    previous = v;
    previous_shift = t;
  }
}

}  // namespace
}  // namespace uh::collette
