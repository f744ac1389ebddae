// The gradient force law does not depend on how finely the object is packed: a ball pressed the
// same depth into the same 10 cm cube packed with 2,000, 10,000 and 50,000 spheres feels the same
// force (within 10 %), through the whole chain (packing, tree, VolumeQuery into a ContactFrame,
// ForceComponent with the coverage product). Reference: the force of the true solids, k times
// the area of the cap's base circle, pi (2 R d - d^2), straight up.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <vector>

#include "uh/collette/mesh_import.hpp"
#include "uh/collette/sphere_packing.hpp"
#include "uh/collette/sphere_tree_builder.hpp"
#include "uh/collette/volume_query.hpp"
#include "uh/forcecomp/force_component.hpp"

namespace uh::controllers {
namespace {

constexpr double kEdge = 0.1;  // the cube [m]

collette::TriangleMesh cube_mesh() {
  collette::TriangleMesh m;
  m.source_name = "cube";
  for (const Vec3& v : std::initializer_list<Vec3>{
           {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}})
    m.vertices.push_back(kEdge * v);
  m.triangles = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                 {3, 7, 6}, {3, 6, 2}, {0, 4, 7}, {0, 7, 3}, {1, 2, 6}, {1, 6, 5}};
  return m;
}

struct Packed {
  collette::SphereTree tree;
  double coverage = 0.0;
  double max_gap = 0.0;
};

TEST(ForceLawCalibration, SameDepthFeelsTheSameForceAtAnySphereCount) {
  auto mesh = collette::validate_mesh(cube_mesh());
  ASSERT_TRUE(mesh) << mesh.error().message;
  std::vector<Packed> packings;
  for (const std::int64_t count : {2000, 10000, 50000}) {
    const auto packing = collette::pack_spheres(*mesh, {.target_sphere_count = count});
    ASSERT_TRUE(packing) << packing.error().message;
    auto tree = collette::build_sphere_tree(packing->spheres);
    ASSERT_TRUE(tree) << tree.error().message;
    packings.push_back({std::move(tree).value(), packing->report.coverage, packing->report.max_gap});
  }
  // the packings differ: coverage rises with the count (the paper law would feel harder by c^2)
  EXPECT_LT(packings[0].coverage, packings[2].coverage);

  // the tool: a ball of radius 3 cm, one sphere (coverage 1), pressed into the top face at the
  // centre and at four points 2 cm off it; the press points average over the packing's grain
  constexpr double kRadius = 0.03;
  const auto ball =
      collette::build_sphere_tree(std::vector<Sphere>{{0.f, 0.f, 0.f, static_cast<float>(kRadius)}});
  ASSERT_TRUE(ball);
  const double k = 2.0e4;  // N/m^2
  const forcecomp::ForceComponent tool(
      {.params = {.stiffness = k, .damping = 0.0}, .mode = forcecomp::ForceMode::k3Dof});
  const std::vector<Vec3> press_points{
      {0.05, 0.05, 0}, {0.03, 0.05, 0}, {0.07, 0.05, 0}, {0.05, 0.03, 0}, {0.05, 0.07, 0}};
  collette::VolumeQuery query;
  auto frame = std::make_unique<ContactFrame>();

  // depths of 10 and 18 mm: about 3 and 5 times the largest surface gap of the coarsest packing
  // (the force dead zone, 3.5 mm at 2,000 spheres), where the contact disk lies mostly below the
  // sparse surface layer. Measured: 30.0, 29.8, 30.5 N at 10 mm and 50.5, 48.8, 48.5 N at 18 mm
  // (solids: 31.4 and 47.5 N)
  const double coarse_gap = packings[0].max_gap;
  for (const double depth : {0.01, 0.018}) {
    ASSERT_GT(depth, 2.5 * coarse_gap) << "a depth within the surface gap measures the gap, not the law";
    const double reference = k * kPi * (2 * kRadius * depth - depth * depth);
    std::vector<double> forces;
    for (const Packed& p : packings) {
      Vec3 sum{};
      for (const Vec3& at : press_points) {
        const Pose world_from_ball{{}, at + Vec3{0, 0, kEdge + kRadius - depth}};
        query.run(p.tree, *ball, Pose{}, world_from_ball, *frame);
        ASSERT_FALSE(frame->truncated);
        sum += tool.evaluate(*frame, tool.body_motion(world_from_ball, {}, {}), {}, p.coverage * 1.0)
                   .wrench.force;
      }
      const Vec3 mean = sum / static_cast<double>(press_points.size());
      std::printf(
          "depth %.0f mm, %d spheres (coverage %.3f, max gap %.1f mm): %.4f N (solids: %.4f N), "
          "off vertical %.2f deg\n",
          depth * 1e3, p.tree.leaf_count(), p.coverage, p.max_gap * 1e3, norm(mean), reference,
          std::acos(std::clamp(mean.z / norm(mean), -1.0, 1.0)) * 180.0 / kPi);
      // straight up, out of the top face
      EXPECT_GT(mean.z, 0.99 * norm(mean));
      forces.push_back(norm(mean));
    }
    const auto [lo, hi] = std::minmax_element(forces.begin(), forces.end());
    EXPECT_LT(*hi, 1.10 * *lo) << "depth " << depth;
    // and near what the solids themselves would give
    for (const double f : forces) EXPECT_NEAR(f, reference, 0.2 * reference) << "depth " << depth;
  }
}

}  // namespace
}  // namespace uh::controllers
