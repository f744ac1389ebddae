// The default solver (conjugate gradients preconditioned by an older factorisation, stopped at a
// residual bound, started from the last acceleration) against the direct reference: the current
// rotated system factorised and solved exactly, from the same state, step by step.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "uh/soft/corotational_fem.hpp"
#include "uh/soft/voxel_lattice.hpp"

namespace uh::soft {
namespace {

// the largest distance [m] between two position sets
double largest_difference(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b) {
  double largest = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) largest = std::max(largest, (a[i] - b[i]).norm());
  return largest;
}

// A box lattice from the origin to `max` of `cells`, and the nodes of its base (held)
struct HeldBox {
  TetMesh mesh;
  std::vector<std::int32_t> base;
};
HeldBox held_box(const Eigen::Vector3d& max, const Eigen::Vector3i& cells) {
  auto mesh = build_box_lattice(Eigen::Vector3d::Zero(), max, cells);
  EXPECT_TRUE(mesh);
  if (!mesh) return {};
  auto base = nodes_in_box(*mesh, Eigen::Vector3d::Zero(), Eigen::Vector3d(max.x(), max.y(), 0.0));
  return {std::move(*mesh), std::move(base)};
}

// a soft solid (E [Pa]), lightly damped
ElasticMaterial soft_material(double young_modulus_pa) {
  return {.young_modulus_pa = young_modulus_pa, .poisson_ratio = 0.4, .density_kg_m3 = 1000.0,
          .stiffness_damping_s = 0.002};
}

TEST(SoftSolver, IteratedStepMatchesDirectSolve) {
  // a soft 6 x 6 x 12 cm column held at its base, its top swung sideways by a load that bends it
  // by tens of degrees, so the rotations drift far from those of the preconditioner
  const Eigen::Vector3d max(0.06, 0.06, 0.12);
  const HeldBox box = held_box(max, Eigen::Vector3i(5, 5, 10));
  const TetMesh* mesh = &box.mesh;
  const auto& base = box.base;
  const ElasticMaterial material = soft_material(2.0e4);
  const SolverOptions iterated{};
  auto fast = CorotationalFem::create(*mesh, material, base, iterated);
  auto direct = CorotationalFem::create(*mesh, material, base, {.direct = true});
  ASSERT_TRUE(fast && direct);
  const auto top = nodes_in_box(*mesh, Eigen::Vector3d(0.0, 0.0, max.z()), max);
  std::vector<Eigen::Vector3d> loads(mesh->nodes.size(), Eigen::Vector3d::Zero());
  constexpr double kDt = 1.0 / 200.0;
  constexpr int kSteps = 300;
  double worst = 0.0;
  double largest_move = 0.0;
  double tilt = 0.0;  // the largest displacement from rest [m]
  int compared = 0;
  for (int step = 0; step < kSteps; ++step) {
    const double swing = std::sin(2.0 * std::numbers::pi * 1.5 * kDt * step);
    for (const std::int32_t node : top) {
      loads[static_cast<std::size_t>(node)] = Eigen::Vector3d(1.2 * swing, 0.4, 0.0) / static_cast<double>(top.size());
    }
    const std::vector<Eigen::Vector3d> start = fast->positions();
    const bool compare = step % 10 == 9;
    if (compare) {
      ASSERT_TRUE(direct->set_state(fast->positions(), fast->velocities()));
    }
    ASSERT_TRUE(fast->step(kDt, loads)) << step;
    const double move = largest_difference(fast->positions(), start);
    largest_move = std::max(largest_move, move);
    tilt = std::max(tilt, largest_difference(fast->positions(), mesh->nodes));
    if (!compare) continue;
    ASSERT_TRUE(direct->step(kDt, loads)) << step;
    // relative to the step's largest node move
    worst = std::max(worst, largest_difference(fast->positions(), direct->positions()) / move);
    ++compared;
  }
  std::printf("%d steps compared: the iterated step is within %.1e of the direct one (of the step's largest "
              "move); %d factorisations in %d steps, largest move %.1f mm per step, %.0f mm from rest\n",
              compared, worst, fast->factorisations(), kSteps, 1e3 * largest_move, 1e3 * tilt);
  // the column bends: its top moves by a third of its height
  EXPECT_GT(tilt, 0.04) << "the load should bend the column far";
  // a relative residual of 1e-6 leaves a step error of that order
  EXPECT_LT(worst, 1e-5);
  // the iterations did the work: most steps were not factorised
  EXPECT_LT(fast->factorisations(), kSteps / 10);
}

// step_response (the compliance a contact feels within one step, by the kept factorisation) against
// the difference of two steps from the same state, one with a load pressed more: a soft block held
// at its base, pressed on a patch of its top and then pressed 0.1 N more there.
TEST(SoftSolver, StepResponseIsTheNextStepsMovePerLoad) {
  const HeldBox box = held_box(Eigen::Vector3d(0.08, 0.08, 0.04), Eigen::Vector3i(8, 8, 4));
  // solved directly, so that the difference of the two steps is exact (the iterations stop at a
  // residual of the whole step's size) and the kept factorisation is the current system's
  auto pressed = CorotationalFem::create(box.mesh, soft_material(5.0e4), box.base, {.direct = true});
  auto more = CorotationalFem::create(box.mesh, soft_material(5.0e4), box.base, {.direct = true});
  ASSERT_TRUE(pressed && more);
  std::vector<Eigen::Vector3d> loads(box.mesh.nodes.size(), Eigen::Vector3d::Zero());
  std::vector<Eigen::Vector3d> moves;
  EXPECT_FALSE(pressed->step_response(loads, moves)) << "no step's system is factorised yet";
  const auto patch = nodes_in_box(box.mesh, Eigen::Vector3d(0.03, 0.03, 0.04), Eigen::Vector3d(0.05, 0.05, 0.04));
  ASSERT_GT(patch.size(), 4u);
  std::vector<Eigen::Vector3d> extra(box.mesh.nodes.size(), Eigen::Vector3d::Zero());
  for (const std::int32_t node : patch) {
    loads[static_cast<std::size_t>(node)] = Eigen::Vector3d(0.3, 0.0, -2.0) / static_cast<double>(patch.size());
    extra[static_cast<std::size_t>(node)] = Eigen::Vector3d(0.0, 0.0, -0.1) / static_cast<double>(patch.size());
  }
  constexpr double kDt = 0.01;
  for (int step = 0; step < 20; ++step) ASSERT_TRUE(pressed->step(kDt, loads));
  ASSERT_TRUE(pressed->step_response(extra, moves));
  ASSERT_TRUE(more->set_state(pressed->positions(), pressed->velocities()));
  std::vector<Eigen::Vector3d> more_loads = loads;
  for (std::size_t n = 0; n < loads.size(); ++n) more_loads[n] += extra[n];
  ASSERT_TRUE(pressed->step(kDt, loads));
  ASSERT_TRUE(more->step(kDt, more_loads));
  double largest = 0.0, error = 0.0, work = 0.0;
  for (std::size_t n = 0; n < loads.size(); ++n) {
    const Eigen::Vector3d difference = more->positions()[n] - pressed->positions()[n];
    largest = std::max(largest, difference.norm());
    error = std::max(error, (moves[n] - difference).norm());
    work += extra[n].dot(moves[n]);
  }
  std::printf("0.1 N more moves the patch %.3f mm in a step; step_response within %.1e of it (of the largest "
              "move); compliance %.2f mm/N\n",
              1e3 * largest, error / largest, 1e3 * work / 0.01);
  EXPECT_GT(largest, 1e-6);
  EXPECT_LT(error, 1e-4 * largest);
  EXPECT_GT(work, 0.0);
}

TEST(SoftSolver, RejectsBadOptions) {
  auto mesh = build_box_lattice(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones(), {1, 1, 1});
  ASSERT_TRUE(mesh);
  EXPECT_FALSE(CorotationalFem::create(*mesh, {}, {}, {.relative_residual = 0.0}));
  EXPECT_FALSE(CorotationalFem::create(*mesh, {}, {}, {.relative_residual = 1.0}));
  EXPECT_FALSE(CorotationalFem::create(*mesh, {}, {}, {.max_iterations = 0}));
}

}  // namespace
}  // namespace uh::soft
