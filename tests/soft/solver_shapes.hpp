#pragma once
// Shapes and materials the solver tests share (solver_test.cpp, background_factorisation_test.cpp).

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <thread>
#include <vector>

#include "uh/soft/corotational_fem.hpp"
#include "uh/soft/voxel_lattice.hpp"

namespace uh::soft {

// the largest distance [m] between two position sets
inline double largest_difference(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b) {
  double largest = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) largest = std::max(largest, (a[i] - b[i]).norm());
  return largest;
}

// A box lattice from the origin to `max` of `cells`, and the nodes of its base (held)
struct HeldBox {
  TetMesh mesh;
  std::vector<std::int32_t> base;
};
inline HeldBox held_box(const Eigen::Vector3d& max, const Eigen::Vector3i& cells) {
  auto mesh = build_box_lattice(Eigen::Vector3d::Zero(), max, cells);
  EXPECT_TRUE(mesh);
  if (!mesh) return {};
  auto base = nodes_in_box(*mesh, Eigen::Vector3d::Zero(), Eigen::Vector3d(max.x(), max.y(), 0.0));
  return {std::move(*mesh), std::move(base)};
}

// a soft solid (E [Pa]), lightly damped
inline ElasticMaterial soft_material(double young_modulus_pa) {
  return {.young_modulus_pa = young_modulus_pa, .poisson_ratio = 0.4, .density_kg_m3 = 1000.0,
          .stiffness_damping_s = 0.002};
}

// a soft 6 x 6 x 12 cm column held at its base
inline HeldBox swinging_column() { return held_box(Eigen::Vector3d(0.06, 0.06, 0.12), Eigen::Vector3i(5, 5, 10)); }

constexpr int kSwingSteps = 300;
struct SwingComparison {
  double worst = 0.0;         // the largest step difference from the direct solve, over the step's largest move
  double largest_move = 0.0;  // [m] per step
  double tilt = 0.0;          // the largest displacement from rest [m]
  int compared = 0;
};

// `fast` (a model of `column`) swung by a load on its top that bends it by tens of degrees, so the
// rotations drift far from those of its preconditioner, `pause_s` [s] of wall time between steps;
// for `steps` steps, every tenth also taken by a direct solve from the same state and compared.
inline SwingComparison swing_against_direct(CorotationalFem& fast, const HeldBox& column, double pause_s,
                                            int steps = kSwingSteps) {
  SwingComparison result;
  const TetMesh& mesh = column.mesh;
  auto direct = CorotationalFem::create(mesh, soft_material(2.0e4), column.base, {.direct = true});
  EXPECT_TRUE(direct);
  if (!direct) return result;
  double height = 0.0;
  for (const Eigen::Vector3d& node : mesh.nodes) height = std::max(height, node.z());
  const auto top = nodes_in_box(mesh, Eigen::Vector3d(-1.0, -1.0, height), Eigen::Vector3d(1.0, 1.0, height));
  std::vector<Eigen::Vector3d> loads(mesh.nodes.size(), Eigen::Vector3d::Zero());
  constexpr double kDt = 1.0 / 200.0;
  for (int step = 0; step < steps; ++step) {
    const double swing = std::sin(2.0 * std::numbers::pi * 1.5 * kDt * step);
    for (const std::int32_t node : top) {
      loads[static_cast<std::size_t>(node)] = Eigen::Vector3d(1.2 * swing, 0.4, 0.0) / static_cast<double>(top.size());
    }
    const std::vector<Eigen::Vector3d> start = fast.positions();
    const bool compare = step % 10 == 9;
    if (compare) {
      EXPECT_TRUE(direct->set_state(fast.positions(), fast.velocities()));
    }
    EXPECT_TRUE(fast.step(kDt, loads)) << step;
    const double move = largest_difference(fast.positions(), start);
    result.largest_move = std::max(result.largest_move, move);
    result.tilt = std::max(result.tilt, largest_difference(fast.positions(), mesh.nodes));
    if (pause_s > 0.0) std::this_thread::sleep_for(std::chrono::duration<double>(pause_s));
    if (!compare) continue;
    EXPECT_TRUE(direct->step(kDt, loads)) << step;
    result.worst = std::max(result.worst, largest_difference(fast.positions(), direct->positions()) / move);
    ++result.compared;
  }
  return result;
}

}  // namespace uh::soft
