// A rigid sphere pressed, quasi-statically and without friction, into a soft block much larger than
// the contact, against Hertz's law F = 4/3 E* sqrt(R) d^1.5 with E* = E / (1 - nu^2) (a rigid
// sphere on an elastic half-space), at indentations up to a tenth of the radius.
//
// The block is a quarter of a square block, pressed at its corner: its two cut faces are symmetry
// planes, on which nodes slide without friction (a stiff penalty on their normal motion), so the
// lattice's cells are a quarter as many for the same size. The sphere's contact is the penalty of
// RigidSphere, iterated to equilibrium.
//
// Two errors make the FEM stiffer than Hertz: linear tetrahedra on cells coarser than the contact
// (radius a = sqrt(R d), 0.16 R to 0.32 R here) and the finite block held at its base. On a
// uniform lattice of the default count over a 10 x 10 x 5 cm block the force is 4 to 27 % above
// Hertz (cells of 0.19 R). A lattice graded from the contact (LatticeRefinement) puts fine cells
// under the sphere and coarse ones far from it, so the block can be much deeper than the contact
// for few more cells: on a 20 x 20 x 20 cm block, 6-12 % above Hertz on 5,832 tets (cells of
// 0.067 R under the sphere); on a 30 x 30 x 30 cm block, 1.5-4.3 % above on 29,184 tets (0.056 R,
// `slow`). Sneddon's exact solution for a sphere is 0.3-1 % below Hertz's at these depths. The
// bounds are the issue's, 15 % and 5 %; each test fails on the uniform lattice of its count.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "uh/soft/corotational_fem.hpp"
#include "uh/soft/rigid_sphere.hpp"
#include "uh/soft/voxel_lattice.hpp"

namespace uh::soft {
namespace {

constexpr double kYoung = 1.0e4;  // [Pa]
constexpr double kPoisson = 0.3;
constexpr double kRadius = 0.03;     // [m], the sphere

double hertz_force(double depth) {
  const double reduced = kYoung / (1.0 - kPoisson * kPoisson);
  return 4.0 / 3.0 * reduced * std::sqrt(kRadius) * std::pow(depth, 1.5);
}

struct Indentation {
  double depth;  // [m]
  double force;  // [N], on the whole block's sphere (four quarters), pushing it out
};

// the nodes on the cut faces x = 0 and y = 0 slide on them: a stiff penalty on their normal motion
void add_symmetry_planes(const TetMesh& mesh, double stiffness, const std::vector<Eigen::Vector3d>& positions,
                         std::vector<NodeContact>& contacts) {
  for (std::size_t n = 0; n < positions.size(); ++n) {
    for (int axis = 0; axis < 2; ++axis) {
      if (mesh.nodes[n][axis] != 0.0) continue;
      NodeContact plane{.node = static_cast<std::int32_t>(n)};
      plane.force[axis] = -stiffness * positions[n][axis];
      plane.stiffness(axis, axis) = stiffness;
      contacts.push_back(plane);
    }
  }
}

// the quarter block [0, w]^2 x [-h, 0] and its lattice
struct Block {
  double half_width;  // w [m]
  double depth;       // h [m]
  int tetrahedra;
  std::optional<LatticeRefinement> refinement = std::nullopt;  // around the corner under the sphere
};

// the shortest cell edge of the lattice (the cells' sides are the axis-aligned edges)
double finest_cell(const TetMesh& mesh) {
  double finest = std::numeric_limits<double>::infinity();
  for (const auto& t : mesh.tets) {
    for (std::size_t i = 0; i < 4; ++i) {
      for (std::size_t j = i + 1; j < 4; ++j) {
        const Eigen::Vector3d edge = mesh.nodes[static_cast<std::size_t>(t[i])] - mesh.nodes[static_cast<std::size_t>(t[j])];
        finest = std::min(finest, edge.cwiseAbs().maxCoeff());
      }
    }
  }
  return finest;
}

// the quarter block, its base held, pressed at its corner by the sphere to R/40, R/20, 3R/40 and
// R/10, each from the last equilibrium
std::vector<Indentation> press(const Block& block) {
  const Eigen::Vector3d min(0.0, 0.0, -block.depth), max(block.half_width, block.half_width, 0.0);
  auto mesh = build_voxel_lattice([](const Eigen::Vector3d&) { return true; },
                                  {.min = min, .max = max, .target_tetrahedra = block.tetrahedra,
                                   .refinement = block.refinement});
  EXPECT_TRUE(mesh);
  const auto base = nodes_in_box(*mesh, min, Eigen::Vector3d(max.x(), max.y(), min.z()));
  // iterations on the first factorisation (the contacts change the system little): one
  // factorisation per test
  auto fem = CorotationalFem::create(*mesh, {.young_modulus_pa = kYoung, .poisson_ratio = kPoisson}, base,
                                     {.max_iterations = 200});
  EXPECT_TRUE(fem) << fem.error().message;
  const double cell = finest_cell(*mesh);
  // a node's contact stiffness a hundred times an element's under the sphere (E times its edge): a
  // pressed node stays inside the sphere by its force over this, under 0.5 % of the indentation
  const double penalty = 100.0 * kYoung * cell;
  const std::vector<Eigen::Vector3d> no_load(mesh->nodes.size(), Eigen::Vector3d::Zero());
  std::vector<Indentation> curve;
  for (int i = 1; i <= 4; ++i) {
    const double depth = kRadius / 10.0 * i / 4.0;
    const RigidSphere sphere{.centre = Eigen::Vector3d(0.0, 0.0, kRadius - depth), .radius_m = kRadius,
                             .penalty_n_per_m = penalty};
    const ContactModel pressed = sphere.contacts();
    const auto contacts = [&](const std::vector<Eigen::Vector3d>& positions, std::vector<NodeContact>& out) {
      pressed(positions, out);
      add_symmetry_planes(*mesh, penalty, positions, out);
    };
    const auto solves = fem->solve_static(no_load, contacts, 100, 1e-7 * kRadius);
    EXPECT_TRUE(solves) << solves.error().message;
    curve.push_back({depth, 4.0 * sphere.force_on_sphere(fem->positions()).z()});
    std::printf("  %zu tets (finest cells %.3f R), d = %.3f R: F = %.4f N, %.3f of Hertz's\n", mesh->tets.size(),
                cell / kRadius, depth / kRadius, curve.back().force, curve.back().force / hertz_force(depth));
  }
  return curve;
}

void expect_hertz(const std::vector<Indentation>& curve, double tolerance, double slope_tolerance) {
  ASSERT_EQ(curve.size(), 4u);
  for (const Indentation& at : curve) EXPECT_NEAR(at.force / hertz_force(at.depth), 1.0, tolerance) << at.depth;
  // the exponent, from R/20 to R/10: Hertz's 1.5, a point load's 1, a flat punch's 1
  const double slope = std::log(curve[3].force / curve[1].force) / std::log(curve[3].depth / curve[1].depth);
  EXPECT_NEAR(slope, 1.5, slope_tolerance);
}

TEST(Hertz, SpherePressedIntoBlockOnDefaultUniformLattice) {
  expect_hertz(press({.half_width = 0.05, .depth = 0.05, .tetrahedra = LatticeOptions{}.target_tetrahedra}), 0.30, 0.15);
}

// about the default count: cells fine within 4 mm of the contact's centre (the largest contact
// radius is 9.5 mm), growing by 1.4 per cell to the faces of a 20 x 20 x 20 cm block (the quarter's
// 10 x 10 x 20 cm)
TEST(Hertz, SpherePressedIntoBlockOnGradedLatticeOfDefaultCost) {
  const Block block{.half_width = 0.1, .depth = 0.2, .tetrahedra = 6000,
                    .refinement = LatticeRefinement{.fine_half_width_m = 0.004, .growth_ratio = 1.4}};
  expect_hertz(press(block), 0.15, 0.1);
}

// the refined reference: 30,000 tets graded by 1.25 from 5 mm around the contact to the faces of a
// 30 x 30 x 30 cm block (about a minute in Release: `slow`)
TEST(Hertz, SpherePressedIntoBlockOnRefinedGradedLattice) {
  const Block block{.half_width = 0.15, .depth = 0.3, .tetrahedra = 30000,
                    .refinement = LatticeRefinement{.fine_half_width_m = 0.005, .growth_ratio = 1.25}};
  expect_hertz(press(block), 0.05, 0.05);
}

}  // namespace
}  // namespace uh::soft
