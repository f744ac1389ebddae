#include "uh/soft/voxel_lattice.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>

namespace uh::soft {
namespace {

using Face = std::array<std::int32_t, 3>;

// how many tetrahedra hold each triangle (sorted node ids)
std::map<Face, int> face_uses(const TetMesh& mesh) {
  static constexpr int kFaces[4][3] = {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}};
  std::map<Face, int> uses;
  for (const auto& t : mesh.tets) {
    for (const auto& f : kFaces) {
      Face face{t[static_cast<std::size_t>(f[0])], t[static_cast<std::size_t>(f[1])], t[static_cast<std::size_t>(f[2])]};
      std::sort(face.begin(), face.end());
      ++uses[face];
    }
  }
  return uses;
}

TEST(VoxelLattice, BoxLatticeFillsTheBoxWithPositiveConformingTets) {
  const Eigen::Vector3d min(-0.1, 0.0, 0.2), max(0.3, 0.1, 0.35);
  const auto mesh = build_box_lattice(min, max, {4, 2, 3});
  ASSERT_TRUE(mesh) << mesh.error().message;
  EXPECT_EQ(mesh->tets.size(), 6u * 4 * 2 * 3);
  EXPECT_EQ(mesh->nodes.size(), 5u * 3 * 4);
  for (const auto& t : mesh->tets) {
    const double v = tet_volume(mesh->nodes[static_cast<std::size_t>(t[0])], mesh->nodes[static_cast<std::size_t>(t[1])],
                                mesh->nodes[static_cast<std::size_t>(t[2])], mesh->nodes[static_cast<std::size_t>(t[3])]);
    EXPECT_GT(v, 0.0);
  }
  EXPECT_NEAR(mesh_volume(*mesh, mesh->nodes), (max - min).prod(), 1e-15);
  // conforming: a face is shared by two tets or lies on the box surface, whose cell faces are cut
  // in two triangles each
  int boundary = 0;
  for (const auto& [face, count] : face_uses(*mesh)) {
    ASSERT_LE(count, 2);
    if (count == 1) ++boundary;
  }
  EXPECT_EQ(boundary, 2 * 2 * (4 * 2 + 2 * 3 + 3 * 4));
}

TEST(VoxelLattice, BallLatticeNearTargetCountAndVolume) {
  const double radius = 0.05;
  const auto inside = [&](const Eigen::Vector3d& p) { return p.norm() < radius; };
  for (const int target : {1000, 5000, 20000}) {
    const auto mesh = build_voxel_lattice(inside, {.min = Eigen::Vector3d::Constant(-radius),
                                                   .max = Eigen::Vector3d::Constant(radius),
                                                   .target_tetrahedra = target});
    ASSERT_TRUE(mesh) << mesh.error().message;
    const auto count = static_cast<double>(mesh->tets.size());
    EXPECT_NEAR(count / target, 1.0, 0.25) << target;
    // a voxelised ball: its volume tends to the ball's as the cells shrink
    const double ball = 4.0 / 3.0 * std::numbers::pi * radius * radius * radius;
    EXPECT_NEAR(mesh_volume(*mesh, mesh->nodes) / ball, 1.0, target >= 5000 ? 0.1 : 0.2) << target;
    for (const auto& [face, uses] : face_uses(*mesh)) ASSERT_LE(uses, 2);
  }
}

TEST(VoxelLattice, RejectsEmptyRegionTargetOrObject) {
  const auto everywhere = [](const Eigen::Vector3d&) { return true; };
  const auto nowhere = [](const Eigen::Vector3d&) { return false; };
  const auto flat = build_voxel_lattice(everywhere, {.max = Eigen::Vector3d(1.0, 0.0, 1.0)});
  ASSERT_FALSE(flat);
  EXPECT_EQ(flat.error().kind, ErrorKind::kInvalid);
  const auto few = build_voxel_lattice(everywhere, {.target_tetrahedra = 5});
  ASSERT_FALSE(few);
  EXPECT_NE(few.error().message.find("target_tetrahedra"), std::string::npos);
  const auto empty = build_voxel_lattice(nowhere, {});
  ASSERT_FALSE(empty);
  EXPECT_EQ(empty.error().kind, ErrorKind::kMesh);
  EXPECT_FALSE(build_box_lattice(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones(), {1, 0, 1}));
}

}  // namespace
}  // namespace uh::soft
