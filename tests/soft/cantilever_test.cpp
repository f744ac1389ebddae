// A cantilever's static tip deflection under an end load against Euler-Bernoulli beam theory,
// delta = P L^3 / (3 E I). Linear tetrahedra are too stiff in bending on coarse meshes (shear
// locking); the error shrinks as the lattice is refined.

#include <gtest/gtest.h>

#include <cmath>

#include "uh/soft/corotational_fem.hpp"
#include "uh/soft/voxel_lattice.hpp"

namespace uh::soft {
namespace {

constexpr double kLength = 0.2;     // [m], along x
constexpr double kThickness = 0.02; // [m], square section
constexpr double kYoung = 1.0e6;    // [Pa]
constexpr double kLoad = 1.0e-3;    // [N], down (-z) at the free end: a tip deflection of L / 1000

// the tip deflection [m] (mean over the free end's nodes) with `across` cells over the thickness
double tip_deflection(int across) {
  const Eigen::Vector3d min(0.0, 0.0, 0.0), max(kLength, kThickness, kThickness);
  auto mesh = build_box_lattice(min, max, {10 * across, across, across});
  EXPECT_TRUE(mesh);
  const auto clamped = nodes_in_box(*mesh, min, Eigen::Vector3d(0.0, kThickness, kThickness));
  auto fem = CorotationalFem::create(*mesh, {.young_modulus_pa = kYoung, .poisson_ratio = 0.3}, clamped);
  EXPECT_TRUE(fem) << fem.error().message;
  const auto tip = nodes_in_box(*mesh, Eigen::Vector3d(kLength, 0.0, 0.0), max);
  std::vector<Eigen::Vector3d> loads(mesh->nodes.size(), Eigen::Vector3d::Zero());
  for (const std::int32_t node : tip) loads[static_cast<std::size_t>(node)].z() = -kLoad / static_cast<double>(tip.size());
  const auto solves = fem->solve_static(loads);
  EXPECT_TRUE(solves) << solves.error().message;
  double sum = 0.0;
  for (const std::int32_t node : tip) {
    const auto i = static_cast<std::size_t>(node);
    sum += mesh->nodes[i].z() - fem->positions()[i].z();
  }
  return sum / static_cast<double>(tip.size());
}

TEST(Cantilever, TipDeflectionConvergesToEulerBernoulli) {
  const double second_moment = std::pow(kThickness, 4) / 12.0;
  const double reference = kLoad * std::pow(kLength, 3) / (3.0 * kYoung * second_moment);
  double previous_error = 1.0;
  for (const int across : {2, 4, 8}) {
    const double error = std::abs(tip_deflection(across) / reference - 1.0);
    std::printf("cantilever %d x %d x %d cells: tip deflection error %.1f %%\n", 10 * across, across, across, 100 * error);
    EXPECT_LT(error, previous_error) << across;
    previous_error = error;
  }
  EXPECT_LT(previous_error, 0.10);
}

}  // namespace
}  // namespace uh::soft
