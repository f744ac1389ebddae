// The default solver (conjugate gradients preconditioned by an older factorisation, stopped at a
// residual bound, started from the last acceleration) against the direct reference: the current
// rotated system factorised and solved exactly, from the same state, step by step.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "solver_shapes.hpp"
#include "uh/soft/block_preconditioner.hpp"

namespace uh::soft {
namespace {

TEST(SoftSolver, IteratedStepMatchesDirectSolve) {
  const HeldBox box = swinging_column();
  auto fast = CorotationalFem::create(box.mesh, soft_material(2.0e4), box.base, {});
  ASSERT_TRUE(fast);
  const SwingComparison swing = swing_against_direct(*fast, box, 0.0);
  std::printf("%d steps compared: the iterated step is within %.1e of the direct one (of the step's largest "
              "move); %d factorisations in %d steps, largest move %.1f mm per step, %.0f mm from rest\n",
              swing.compared, swing.worst, fast->factorisations(), kSwingSteps, 1e3 * swing.largest_move,
              1e3 * swing.tilt);
  // the column bends: its top moves by a third of its height
  EXPECT_GT(swing.tilt, 0.04) << "the load should bend the column far";
  // a relative residual of 1e-6 leaves a step error of that order
  EXPECT_LT(swing.worst, 1e-5);
  // the iterations did the work: most steps were not factorised
  EXPECT_LT(fast->factorisations(), kSwingSteps / 10);
}

// The preconditioner's float copy of a factorisation against a dense Cholesky solve of the same
// system: a symmetric positive definite matrix of 12 nodes' 3 x 3 blocks, banded as a lattice's.
TEST(SoftSolver, BlockPreconditionerSolvesTheFactorisedSystem) {
  const int n = 3 * 12;
  Eigen::MatrixXd random = Eigen::MatrixXd::Random(n, n);
  Eigen::MatrixXd dense = random * random.transpose() + n * Eigen::MatrixXd::Identity(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      if (std::abs(i / 3 - j / 3) > 2) dense(i, j) = 0.0;  // a banded block pattern, as a lattice's
  dense += 4.0 * n * Eigen::MatrixXd::Identity(n, n);  // diagonally dominant again
  const Eigen::MatrixXd dense_lower = dense.triangularView<Eigen::Lower>();
  const Eigen::SparseMatrix<double> lower = dense_lower.sparseView();
  SystemFactorisation factorised(lower);
  ASSERT_EQ(factorised.info(), Eigen::Success);
  BlockPreconditioner preconditioner;
  EXPECT_TRUE(preconditioner.empty());
  preconditioner.keep(factorised);
  const Eigen::VectorXd residual = Eigen::VectorXd::Random(n);
  Eigen::VectorXd solved;
  preconditioner.apply(residual, solved);
  const Eigen::VectorXd reference = dense.llt().solve(residual);  // dense Cholesky, no sparse code
  EXPECT_LT((solved - reference).norm(), 1e-5 * reference.norm());
  // swapped out, the other holds it and solves the same
  BlockPreconditioner other;
  other.swap(preconditioner);
  EXPECT_TRUE(preconditioner.empty());
  Eigen::VectorXd again;
  other.apply(residual, again);
  EXPECT_EQ(again, solved);
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
