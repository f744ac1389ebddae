// Simulation rate of a soft block against its tetrahedron count: one implicit corotational step
// (rotations, forces, assembly, solve) per iteration, the block clamped at its base and its top
// face pushed by a swinging load. items_per_second is steps per second. Two solvers in the same
// run: the default (conjugate gradients preconditioned by an earlier factorisation) and the direct
// reference (the current system factorised every step).

#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>

#include "uh/soft/corotational_fem.hpp"
#include "uh/soft/voxel_lattice.hpp"

namespace {

using namespace uh::soft;

void run_block(benchmark::State& state, const SolverOptions& solver) {
  // a 10 cm x 10 cm x 5 cm block of a soft tissue-like material, its base held
  const Eigen::Vector3d min(-0.05, -0.05, 0.0), max(0.05, 0.05, 0.05);
  auto mesh = build_voxel_lattice([](const Eigen::Vector3d&) { return true; },
                                  {.min = min, .max = max, .target_tetrahedra = static_cast<int>(state.range(0))});
  if (!mesh) {
    state.SkipWithError(mesh.error().message.c_str());
    return;
  }
  const auto fixed = nodes_in_box(*mesh, min - Eigen::Vector3d::Constant(1e-9), Eigen::Vector3d(0.05, 0.05, 1e-9));
  auto fem = CorotationalFem::create(*mesh, {.young_modulus_pa = 5.0e4, .poisson_ratio = 0.45,
                                             .density_kg_m3 = 1000.0, .stiffness_damping_s = 0.005}, fixed, solver);
  if (!fem) {
    state.SkipWithError(fem.error().message.c_str());
    return;
  }
  // the top face pushed sideways and down by a load that swings at 2 Hz, so the block keeps moving
  constexpr double kDt = 1.0 / 200.0;
  std::vector<std::int32_t> top;
  for (std::size_t i = 0; i < mesh->nodes.size(); ++i) {
    if (mesh->nodes[i].z() > max.z() - 1e-9) top.push_back(static_cast<std::int32_t>(i));
  }
  std::vector<Eigen::Vector3d> loads(mesh->nodes.size(), Eigen::Vector3d::Zero());
  const Eigen::Vector3d total_load(2.0, 0.0, -2.0);  // [N]
  int step = 0;
  const auto advance = [&] {
    const double swing = std::sin(2.0 * std::numbers::pi * 2.0 * kDt * step++);
    for (const std::int32_t node : top) loads[static_cast<std::size_t>(node)] = swing * total_load / static_cast<double>(top.size());
    return static_cast<bool>(fem->step(kDt, loads));
  };
  // the first step factorises; the steady state is what the simulation thread sees
  if (!advance()) state.SkipWithError("the first step failed");
  const int factorised_before = fem->factorisations();
  const std::int64_t turns_before = fem->rotation_turns();
  double iterations = 0.0;
  for (auto _ : state) {
    if (!advance()) state.SkipWithError("the step failed");
    iterations += fem->last_iterations();
  }
  state.counters["cg_iterations_per_step"] = iterations / static_cast<double>(state.iterations());
  state.counters["rotation_turns_per_tet"] = static_cast<double>(fem->rotation_turns() - turns_before) /
                                             static_cast<double>(state.iterations() * mesh->tets.size());
  state.SetItemsProcessed(state.iterations());
  state.counters["tets"] = static_cast<double>(mesh->tets.size());
  state.counters["dofs"] = fem->free_dofs();
  state.counters["factorisations_per_step"] =
      static_cast<double>(fem->factorisations() - factorised_before) / static_cast<double>(state.iterations());
}
void BM_SoftBlockStep(benchmark::State& state) { run_block(state, {}); }
void BM_SoftBlockStepDirect(benchmark::State& state) { run_block(state, {.direct = true}); }
BENCHMARK(BM_SoftBlockStep)->Arg(1000)->Arg(5000)->Arg(20000)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_SoftBlockStepDirect)->Arg(1000)->Arg(5000)->Arg(20000)->Unit(benchmark::kMillisecond)->MinTime(2.0);

}  // namespace
BENCHMARK_MAIN();
