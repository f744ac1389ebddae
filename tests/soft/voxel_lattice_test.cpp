#include "uh/soft/voxel_lattice.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
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

// the distinct node coordinates along `axis` (the grid lines)
std::vector<double> grid_lines(const TetMesh& mesh, int axis) {
  std::vector<double> lines;
  for (const auto& n : mesh.nodes) lines.push_back(n[axis]);
  std::sort(lines.begin(), lines.end());
  lines.erase(std::unique(lines.begin(), lines.end()), lines.end());
  return lines;
}

// the largest dihedral angle [rad] of a tetrahedron
double largest_dihedral(const TetMesh& mesh, const std::array<std::int32_t, 4>& t) {
  static constexpr int kEdges[6][4] = {{0, 1, 2, 3}, {0, 2, 1, 3}, {0, 3, 1, 2}, {1, 2, 0, 3}, {1, 3, 0, 2}, {2, 3, 0, 1}};
  double largest = 0.0;
  for (const auto& e : kEdges) {
    const auto at = [&](int i) { return mesh.nodes[static_cast<std::size_t>(t[static_cast<std::size_t>(e[i])])]; };
    const Eigen::Vector3d axis = (at(1) - at(0)).normalized();
    Eigen::Vector3d u = at(2) - at(0), v = at(3) - at(0);
    u -= u.dot(axis) * axis;
    v -= v.dot(axis) * axis;
    largest = std::max(largest, std::acos(std::clamp(u.normalized().dot(v.normalized()), -1.0, 1.0)));
  }
  return largest;
}

TEST(VoxelLattice, GradedLatticeIsConformingAndGrowsByTheRatioFromThePoint) {
  const Eigen::Vector3d min(-0.1, -0.05, -0.08), max(0.1, 0.05, 0.0);
  const LatticeRefinement refinement{.point = Eigen::Vector3d(0.013, 0.0, 0.0), .fine_half_width_m = 0.01,
                                     .growth_ratio = 1.3};
  const auto mesh = build_voxel_lattice([](const Eigen::Vector3d&) { return true; },
                                        {.min = min, .max = max, .target_tetrahedra = 8000, .refinement = refinement});
  ASSERT_TRUE(mesh) << mesh.error().message;
  EXPECT_NEAR(static_cast<double>(mesh->tets.size()) / 8000.0, 1.0, 0.25);
  EXPECT_NEAR(mesh_volume(*mesh, mesh->nodes), (max - min).prod(), 1e-12);
  for (const auto& [face, uses] : face_uses(*mesh)) ASSERT_LE(uses, 2);
  // every tetrahedron is a path simplex of its box: positive, no dihedral angle above 90 degrees
  for (const auto& t : mesh->tets) {
    EXPECT_GT(tet_volume(mesh->nodes[static_cast<std::size_t>(t[0])], mesh->nodes[static_cast<std::size_t>(t[1])],
                         mesh->nodes[static_cast<std::size_t>(t[2])], mesh->nodes[static_cast<std::size_t>(t[3])]),
              0.0);
    ASSERT_LE(largest_dihedral(*mesh, t), std::numbers::pi / 2 + 1e-9);
  }
  for (int axis = 0; axis < 3; ++axis) {
    const std::vector<double> lines = grid_lines(*mesh, axis);
    EXPECT_EQ(lines.front(), min[axis]);
    EXPECT_EQ(lines.back(), max[axis]);
    // the point is a grid node; the finest cells are within the fine zone, and cells grow away
    // from it by at most the ratio
    EXPECT_TRUE(std::find(lines.begin(), lines.end(), refinement.point[axis]) != lines.end()) << axis;
    std::vector<double> sizes;
    for (std::size_t i = 0; i + 1 < lines.size(); ++i) sizes.push_back(lines[i + 1] - lines[i]);
    ASSERT_GE(sizes.size(), 2u);
    const auto [smallest, largest] = std::minmax_element(sizes.begin(), sizes.end());
    const double finest = *smallest;
    EXPECT_GT(*largest, 2.0 * finest) << axis;  // it is graded
    for (std::size_t i = 0; i + 1 < sizes.size(); ++i) {
      const double ratio = std::max(sizes[i], sizes[i + 1]) / std::min(sizes[i], sizes[i + 1]);
      EXPECT_LE(ratio, refinement.growth_ratio * (1.0 + 1e-9)) << axis << " " << i;
      const double centre = 0.5 * (lines[i] + lines[i + 1]);
      if (std::abs(centre - refinement.point[axis]) < refinement.fine_half_width_m) {
        EXPECT_LT(sizes[i], 1.01 * finest * refinement.growth_ratio) << axis << " " << i;
      }
      // away from the point a cell is no smaller than its neighbour nearer the point
      if (lines[i] >= refinement.point[axis]) {
        EXPECT_GE(sizes[i + 1], sizes[i] * (1.0 - 1e-9)) << axis << " " << i;
      }
      if (lines[i + 1] <= refinement.point[axis]) {
        EXPECT_LE(sizes[i + 1], sizes[i] * (1.0 + 1e-9)) << axis << " " << i;
      }
    }
  }
}

TEST(VoxelLattice, RejectsABadRefinement) {
  const auto everywhere = [](const Eigen::Vector3d&) { return true; };
  for (const LatticeRefinement& bad : {LatticeRefinement{.growth_ratio = 0.9}, LatticeRefinement{.growth_ratio = 3.0},
                                       LatticeRefinement{.fine_half_width_m = -1.0},
                                       LatticeRefinement{.point = Eigen::Vector3d(std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0)}}) {
    const auto mesh = build_voxel_lattice(everywhere, {.refinement = bad});
    ASSERT_FALSE(mesh);
    EXPECT_EQ(mesh.error().kind, ErrorKind::kInvalid);
    EXPECT_NE(mesh.error().message.find("refinement"), std::string::npos) << mesh.error().message;
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
