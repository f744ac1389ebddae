// A free body's motion: internal forces sum to zero, so momentum is kept and the centre of mass
// moves in a straight line; a rigid rotation stresses nothing; a stretched body recovers its volume.

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "uh/soft/corotational_fem.hpp"
#include "uh/soft/voxel_lattice.hpp"

namespace uh::soft {
namespace {

constexpr double kSide = 0.1;

CorotationalFem free_cube(const ElasticMaterial& material) {
  auto mesh = build_box_lattice(Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(kSide), {4, 4, 4});
  EXPECT_TRUE(mesh);
  auto fem = CorotationalFem::create(*mesh, material, {});
  EXPECT_TRUE(fem) << fem.error().message;
  return std::move(fem).value();
}

Eigen::Vector3d momentum(const CorotationalFem& fem) {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < fem.velocities().size(); ++i) p += fem.node_masses()[i] * fem.velocities()[i];
  return p;
}

Eigen::Vector3d centre_of_mass(const CorotationalFem& fem) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double mass = 0.0;
  for (std::size_t i = 0; i < fem.positions().size(); ++i) {
    sum += fem.node_masses()[i] * fem.positions()[i];
    mass += fem.node_masses()[i];
  }
  return sum / mass;
}

TEST(SoftDynamics, FreeBodyKeepsMomentumAndRecoversVolume) {
  auto fem = free_cube({.young_modulus_pa = 1.0e4, .density_kg_m3 = 1000.0, .stiffness_damping_s = 0.01});
  const double rest_volume = mesh_volume(fem.mesh(), fem.positions());
  EXPECT_NEAR(rest_volume, kSide * kSide * kSide, 1e-15);
  // stretched by 10 % along x, and thrown
  const Eigen::Vector3d throw_velocity(0.1, 0.0, -0.05);
  std::vector<Eigen::Vector3d> stretched = fem.positions();
  for (auto& p : stretched) p.x() *= 1.1;
  ASSERT_TRUE(fem.set_state(stretched, std::vector<Eigen::Vector3d>(stretched.size(), throw_velocity)));
  const Eigen::Vector3d start = centre_of_mass(fem);
  double total_mass = 0.0;
  for (const double m : fem.node_masses()) total_mass += m;
  EXPECT_NEAR(mesh_volume(fem.mesh(), fem.positions()) / rest_volume, 1.1, 1e-12);

  const std::vector<Eigen::Vector3d> no_load(fem.positions().size(), Eigen::Vector3d::Zero());
  constexpr double kDt = 1e-3;
  constexpr int kSteps = 2000;
  for (int step = 0; step < kSteps; ++step) ASSERT_TRUE(fem.step(kDt, no_load));
  EXPECT_LT((momentum(fem) - total_mass * throw_velocity).norm(), 1e-9 * total_mass * throw_velocity.norm());
  EXPECT_LT((centre_of_mass(fem) - (start + kSteps * kDt * throw_velocity)).norm(), 1e-9);
  EXPECT_NEAR(mesh_volume(fem.mesh(), fem.positions()) / rest_volume, 1.0, 0.01);
}

TEST(SoftDynamics, RigidRotationStressesNothing) {
  // a linear FEM pulls a rotated body back towards its rest orientation; corotation does not
  auto fem = free_cube({.young_modulus_pa = 1.0e5});
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.8, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  const Eigen::Vector3d shift(0.3, -0.1, 0.2);
  std::vector<Eigen::Vector3d> turned = fem.positions();
  for (auto& p : turned) p = rotation * p + shift;
  ASSERT_TRUE(fem.set_state(turned, fem.velocities()));
  const std::vector<Eigen::Vector3d> start = fem.positions();
  const std::vector<Eigen::Vector3d> no_load(start.size(), Eigen::Vector3d::Zero());
  for (int step = 0; step < 100; ++step) ASSERT_TRUE(fem.step(1e-3, no_load));
  for (std::size_t i = 0; i < start.size(); ++i) EXPECT_LT((fem.positions()[i] - start[i]).norm(), 1e-12 * kSide);
}

TEST(SoftDynamics, InvertedCubeTurnsBackOut) {
  // the cube turned inside out through its centre (x -> c - x / 2): every tetrahedron inverted; the
  // rotations stay proper (no reflection), and the elastic forces bring back the rest volume
  auto fem = free_cube({.young_modulus_pa = 1.0e4, .mass_damping_per_s = 5.0});
  const double rest_volume = mesh_volume(fem.mesh(), fem.positions());
  std::vector<Eigen::Vector3d> inverted = fem.positions();
  for (auto& p : inverted) p = Eigen::Vector3d::Constant(kSide) - 0.5 * p;
  ASSERT_TRUE(fem.set_state(inverted, fem.velocities()));
  EXPECT_LT(mesh_volume(fem.mesh(), fem.positions()), 0.0);
  const std::vector<Eigen::Vector3d> no_load(fem.positions().size(), Eigen::Vector3d::Zero());
  for (int step = 0; step < 3000; ++step) ASSERT_TRUE(fem.step(1e-3, no_load)) << step;
  EXPECT_NEAR(mesh_volume(fem.mesh(), fem.positions()) / rest_volume, 1.0, 0.01);
  EXPECT_GT(fem.rotation_turns(), 0);  // the inverted elements took the turning path
}

}  // namespace
}  // namespace uh::soft
