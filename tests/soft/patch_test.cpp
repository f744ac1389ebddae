// The constant-strain patch test: a linear displacement field imposed on a body's boundary is the
// exact solution inside, for any mesh of linear tetrahedra, also after a large rotation of the field.

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "uh/soft/corotational_fem.hpp"
#include "uh/soft/voxel_lattice.hpp"

namespace uh::soft {
namespace {

const Eigen::Vector3d kMin(0.0, 0.0, 0.0);
const Eigen::Vector3d kMax(0.1, 0.08, 0.06);

bool on_boundary(const Eigen::Vector3d& p) {
  constexpr double kEps = 1e-12;
  return ((p - kMin).array().abs() < kEps).any() || ((p - kMax).array().abs() < kEps).any();
}

// the largest distance of an interior node from `field` at its rest position, over the largest
// displacement the field makes
double patch_error(const Eigen::Matrix3d& gradient, const Eigen::Vector3d& shift) {
  auto mesh = build_box_lattice(kMin, kMax, {5, 4, 3});
  EXPECT_TRUE(mesh);
  std::vector<std::int32_t> boundary;
  for (std::size_t i = 0; i < mesh->nodes.size(); ++i) {
    if (on_boundary(mesh->nodes[i])) boundary.push_back(static_cast<std::int32_t>(i));
  }
  const auto field = [&](const Eigen::Vector3d& rest) -> Eigen::Vector3d { return gradient * rest + shift; };
  auto fem = CorotationalFem::create(*mesh, {.young_modulus_pa = 2.0e5, .poisson_ratio = 0.35}, boundary);
  EXPECT_TRUE(fem) << fem.error().message;
  for (const std::int32_t node : boundary) {
    EXPECT_TRUE(fem->hold(node, field(mesh->nodes[static_cast<std::size_t>(node)])));
  }
  const std::vector<Eigen::Vector3d> no_load(mesh->nodes.size(), Eigen::Vector3d::Zero());
  const auto solves = fem->solve_static(no_load);
  EXPECT_TRUE(solves) << solves.error().message;
  double error = 0.0;
  double largest = 0.0;
  int interior = 0;
  for (std::size_t i = 0; i < mesh->nodes.size(); ++i) {
    const Eigen::Vector3d expected = field(mesh->nodes[i]);
    largest = std::max(largest, (expected - mesh->nodes[i]).norm());
    if (fem->is_fixed(static_cast<std::int32_t>(i))) continue;
    ++interior;
    error = std::max(error, (fem->positions()[i] - expected).norm());
  }
  EXPECT_EQ(interior, 4 * 3 * 2);
  return error / largest;
}

TEST(PatchTest, ConstantStrainIsExact) {
  Eigen::Matrix3d strain;
  strain << 2e-3, 5e-4, -3e-4,
            5e-4, -1e-3, 8e-4,
            -3e-4, 8e-4, 1.5e-3;
  EXPECT_LT(patch_error(Eigen::Matrix3d::Identity() + strain, Eigen::Vector3d(1e-3, -2e-3, 5e-4)), 1e-9);
}

TEST(PatchTest, RotatedConstantStrainIsExact) {
  // a 40 degree rotation of the field: the iterations with updated rotations converge to it (a
  // linear FEM reproduces it too when every boundary node is held; the rigid-rotation test of
  // dynamics_test.cpp is the one only corotation passes)
  Eigen::Matrix3d stretch = Eigen::Matrix3d::Identity();
  stretch.diagonal() << 1.05, 0.97, 1.02;
  stretch(0, 1) = stretch(1, 0) = 0.01;
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  EXPECT_LT(patch_error(rotation * stretch, Eigen::Vector3d(0.01, 0.0, -0.02)), 1e-9);
}

TEST(CorotationalFem, RejectsBadMaterialNodesAndLoads) {
  auto mesh = build_box_lattice(kMin, kMax, {1, 1, 1});
  ASSERT_TRUE(mesh);
  EXPECT_FALSE(CorotationalFem::create(*mesh, {.poisson_ratio = 0.5}, {}));
  EXPECT_FALSE(CorotationalFem::create(*mesh, {.young_modulus_pa = -1.0}, {}));
  EXPECT_FALSE(CorotationalFem::create(*mesh, {}, {99}));
  auto fem = CorotationalFem::create(*mesh, {}, {});
  ASSERT_TRUE(fem);
  const std::vector<Eigen::Vector3d> no_load(mesh->nodes.size(), Eigen::Vector3d::Zero());
  EXPECT_FALSE(fem->solve_static(no_load));  // a free body has no equilibrium
  EXPECT_FALSE(fem->step(1e-3, {}));
  EXPECT_FALSE(fem->step(0.0, no_load));
  EXPECT_FALSE(fem->hold(0, Eigen::Vector3d::Zero()));  // not a fixed node
  EXPECT_FALSE(fem->set_state({}, fem->velocities()));
  auto held = CorotationalFem::create(*mesh, {}, {0});
  ASSERT_TRUE(held);
  const auto stray = [](const std::vector<Eigen::Vector3d>&, std::vector<NodeContact>& contacts) {
    contacts.push_back({.node = 99});
  };
  EXPECT_FALSE(held->solve_static(no_load, stray));  // a contact on no node
}

}  // namespace
}  // namespace uh::soft
