// The solver with its factorisations on a worker thread (CorotationalFem::factorise_in_background,
// as a session's simulation thread runs it) against the direct reference, step by step: the worker's
// preconditioners are taken while the steps go on, and every step still reaches its residual bound.
// Also under ThreadSanitizer (label "threads").

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "solver_shapes.hpp"

namespace uh::soft {
namespace {

TEST(SoftSolverThreads, BackgroundFactorisationsKeepTheStepsExact) {
  const HeldBox column = swinging_column();
  auto fast = CorotationalFem::create(column.mesh, soft_material(2.0e4), column.base, {});
  ASSERT_TRUE(fast);
  fast->factorise_in_background(true);
  // a simulation thread's pace (200 Hz), so that the worker's factorisations arrive between steps
  const SwingComparison swing = swing_against_direct(*fast, column, 0.005);
  std::printf("%d steps compared: within %.1e of the direct step; %d factorisations in place, %d on the worker\n",
              swing.compared, swing.worst, fast->factorisations(), fast->background_factorisations());
  EXPECT_GT(swing.tilt, 0.04) << "the load should bend the column far";
  EXPECT_LT(swing.worst, 1e-5);
  // the rotations drift far: the worker refactorised, and its preconditioners were used
  EXPECT_GE(fast->background_factorisations(), 1);
  fast->factorise_in_background(false);  // ends the worker; the steps go on in place
  std::vector<Eigen::Vector3d> loads(column.mesh.nodes.size(), Eigen::Vector3d::Zero());
  EXPECT_TRUE(fast->step(0.005, loads));
}

// The element pass on two threads (assemble_on_two_threads) sums the same terms in the same order
// as on one: every step's positions are bit for bit those of a model on one thread.
TEST(SoftSolverThreads, TheElementPassOnTwoThreadsGivesTheSameSteps) {
  const HeldBox column = swinging_column();
  auto one = CorotationalFem::create(column.mesh, soft_material(2.0e4), column.base, {});
  auto two = CorotationalFem::create(column.mesh, soft_material(2.0e4), column.base, {});
  ASSERT_TRUE(one && two);
  two->assemble_on_two_threads(true);
  std::vector<Eigen::Vector3d> loads(column.mesh.nodes.size(), Eigen::Vector3d::Zero());
  for (int step = 0; step < 60; ++step) {
    for (std::size_t n = 0; n < loads.size(); ++n)
      if (column.mesh.nodes[n].z() > 0.11) loads[n] = Eigen::Vector3d(0.05 * std::sin(0.1 * step), 0.02, -0.01);
    ASSERT_TRUE(one->step(0.005, loads));
    ASSERT_TRUE(two->step(0.005, loads));
    ASSERT_EQ(largest_difference(one->positions(), two->positions()), 0.0) << "step " << step;
  }
  EXPECT_GT(largest_difference(two->positions(), column.mesh.nodes), 1e-3) << "the column must move";
  EXPECT_EQ(one->rotation_turns(), two->rotation_turns());
}

// a model moved while its worker runs keeps working (the worker is its own object)
TEST(SoftSolverThreads, AModelMovedWithItsWorkerStillSteps) {
  const HeldBox column = swinging_column();
  auto created = CorotationalFem::create(column.mesh, soft_material(2.0e4), column.base, {});
  ASSERT_TRUE(created);
  created->factorise_in_background(true);
  CorotationalFem moved = std::move(*created);
  const SwingComparison swing = swing_against_direct(moved, column, 0.002, 60);
  EXPECT_EQ(swing.compared, 6);
  EXPECT_LT(swing.worst, 1e-5);
}

}  // namespace
}  // namespace uh::soft
