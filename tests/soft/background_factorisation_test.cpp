// The solver with its factorisations on a worker thread (CorotationalFem::factorise_in_background,
// as a session's simulation thread runs it) against the direct reference, step by step: the worker's
// preconditioners are taken while the steps go on, and every step still reaches its residual bound.
// Also under ThreadSanitizer (label "threads").

#include <gtest/gtest.h>

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
