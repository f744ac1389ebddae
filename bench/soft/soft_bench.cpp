// Simulation rate of a soft block against its tetrahedron count: one implicit corotational step
// (rotations, forces, assembly, solve) per iteration, the block clamped at its base and its top
// face pushed by a swinging load. items_per_second is steps per second. Two solvers in the same
// run: the default (conjugate gradients preconditioned by an earlier factorisation) and the direct
// reference (the current system factorised every step). Also: the packing riding along (each
// step's deform_spheres and SphereTree::refit, and the rebuild a step makes instead of the refit
// when the tree is too distorted) against the sphere count, and the memory a block's
// model and solver hold against its tetrahedron count.

#include <benchmark/benchmark.h>
#include <malloc.h>
#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>

#include "uh/collette/sphere_tree.hpp"
#include "uh/collette/sphere_tree_builder.hpp"
#include "uh/soft/corotational_fem.hpp"
#include "uh/soft/soft_body.hpp"
#include "uh/soft/voxel_lattice.hpp"

namespace {

using namespace uh::soft;
using uh::Sphere;

// a 10 cm x 10 cm x 5 cm block of a soft tissue-like material, its base held
const Eigen::Vector3d kBlockMin(-0.05, -0.05, 0.0), kBlockMax(0.05, 0.05, 0.05);
const ElasticMaterial kTissue{.young_modulus_pa = 5.0e4, .poisson_ratio = 0.45, .density_kg_m3 = 1000.0,
                              .stiffness_damping_s = 0.005};
constexpr double kDt = 1.0 / 200.0;

// the block's top face (its highest nodes) pushed sideways and down by a load that swings at 2 Hz, so it keeps moving
class SwungBlock {
 public:
  explicit SwungBlock(CorotationalFem fem) : fem_(std::move(fem)), loads_(fem_.mesh().nodes.size(), Eigen::Vector3d::Zero()) {
    double top = -std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3d& node : fem_.mesh().nodes) top = std::max(top, node.z());
    for (std::size_t i = 0; i < fem_.mesh().nodes.size(); ++i) {
      if (fem_.mesh().nodes[i].z() > top - 1e-9) top_.push_back(static_cast<std::int32_t>(i));
    }
  }
  bool advance() {
    const Eigen::Vector3d total_load(2.0, 0.0, -2.0);  // [N]
    const double swing = std::sin(2.0 * std::numbers::pi * 2.0 * kDt * step_++);
    for (const std::int32_t node : top_) loads_[static_cast<std::size_t>(node)] = swing * total_load / static_cast<double>(top_.size());
    return static_cast<bool>(fem_.step(kDt, loads_));
  }
  CorotationalFem& fem() { return fem_; }

 private:
  CorotationalFem fem_;
  std::vector<Eigen::Vector3d> loads_;
  std::vector<std::int32_t> top_;
  int step_ = 0;
};

std::vector<std::int32_t> base_nodes(const TetMesh& mesh) {
  return nodes_in_box(mesh, kBlockMin - Eigen::Vector3d::Constant(1e-9), Eigen::Vector3d(kBlockMax.x(), kBlockMax.y(), 1e-9));
}

// the block on about `tetrahedra` tets; none (and the state skipped with the error) on failure
std::optional<SwungBlock> make_block(benchmark::State& state, int tetrahedra, const SolverOptions& solver,
                                     bool two_threads = false) {
  auto mesh = build_voxel_lattice([](const Eigen::Vector3d&) { return true; },
                                  {.min = kBlockMin, .max = kBlockMax, .target_tetrahedra = tetrahedra});
  if (!mesh) {
    state.SkipWithError(mesh.error().message.c_str());
    return std::nullopt;
  }
  const auto fixed = base_nodes(*mesh);
  auto fem = CorotationalFem::create(std::move(mesh).value(), kTissue, fixed, solver);
  if (!fem) {
    state.SkipWithError(fem.error().message.c_str());
    return std::nullopt;
  }
  fem->assemble_on_two_threads(two_threads);
  return SwungBlock(std::move(fem).value());
}

void run_block(benchmark::State& state, const SolverOptions& solver, bool two_threads = false) {
  auto block = make_block(state, static_cast<int>(state.range(0)), solver, two_threads);
  if (!block) return;
  const CorotationalFem* fem = &block->fem();
  const TetMesh* mesh = &fem->mesh();
  // the first step factorises; the steady state is what the simulation thread sees
  if (!block->advance()) state.SkipWithError("the first step failed");
  const int factorised_before = fem->factorisations();
  const std::int64_t turns_before = fem->rotation_turns();
  double iterations = 0.0;
  for (auto _ : state) {
    if (!block->advance()) state.SkipWithError("the step failed");
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
// the element pass on two threads (CorotationalFem::assemble_on_two_threads, as a session's
// simulation thread runs it): wall time, against the one-thread default's wall time in the same run
void BM_SoftBlockStepTwoThreads(benchmark::State& state) { run_block(state, {}, true); }
BENCHMARK(BM_SoftBlockStep)->Arg(1000)->Arg(5000)->Arg(20000)->Unit(benchmark::kMillisecond)->MinTime(2.0)->UseRealTime();
BENCHMARK(BM_SoftBlockStepTwoThreads)->Arg(1000)->Arg(5000)->Arg(20000)->Unit(benchmark::kMillisecond)->MinTime(2.0)->UseRealTime();
BENCHMARK(BM_SoftBlockStepDirect)->Arg(1000)->Arg(5000)->Arg(20000)->Unit(benchmark::kMillisecond)->MinTime(2.0);

// non-overlapping spheres on a grid filling the block, about `count` of them
std::vector<Sphere> block_packing(int count) {
  const Eigen::Vector3d extent = kBlockMax - kBlockMin;
  const double spacing = std::cbrt(extent.prod() / count);
  std::vector<Sphere> leaves;
  for (double z = kBlockMin.z() + 0.5 * spacing; z < kBlockMax.z(); z += spacing)
    for (double y = kBlockMin.y() + 0.5 * spacing; y < kBlockMax.y(); y += spacing)
      for (double x = kBlockMin.x() + 0.5 * spacing; x < kBlockMax.x(); x += spacing)
        leaves.push_back({static_cast<float>(x), static_cast<float>(y), static_cast<float>(z), static_cast<float>(0.45 * spacing)});
  return leaves;
}

// A packing of about `count` spheres embedded in the swung block of 5,000 tets, after 40 steps (a
// deformed state), with its tree.
struct RidingPacking {
  SoftBodyModel body;
  uh::collette::SphereTree tree;
  std::vector<Eigen::Vector3d> positions;  // the deformed nodes
  std::vector<Sphere> moved;
};

std::optional<RidingPacking> make_riding_packing(benchmark::State& state, int count) {
  const std::vector<Sphere> leaves = block_packing(count);
  SoftBodyParams params{.material = kTissue, .target_tetrahedra = 5000,
                        .fixed = Box{.min = kBlockMin, .max = Eigen::Vector3d(kBlockMax.x(), kBlockMax.y(), 1e-3)}};
  auto body = build_soft_body([](const Eigen::Vector3d&) { return true; }, leaves, params);
  auto tree = uh::collette::build_sphere_tree(leaves);
  if (!body || !tree) {
    state.SkipWithError(!body ? body.error().message.c_str() : tree.error().message.c_str());
    return std::nullopt;
  }
  auto fem = CorotationalFem::create(body->mesh, body->material, body->fixed);
  if (!fem) {
    state.SkipWithError(fem.error().message.c_str());
    return std::nullopt;
  }
  SwungBlock block(std::move(fem).value());
  for (int step = 0; step < 40; ++step) block.advance();
  RidingPacking packing{std::move(body).value(), std::move(tree).value(), block.fem().positions(), std::vector<Sphere>(leaves.size())};
  deform_spheres(packing.body, packing.positions, packing.moved);
  double largest_move = 0.0;
  for (std::size_t i = 0; i < packing.positions.size(); ++i)
    largest_move = std::max(largest_move, (packing.positions[i] - packing.body.mesh.nodes[i]).norm());
  state.counters["spheres"] = static_cast<double>(leaves.size());
  state.counters["tets"] = static_cast<double>(packing.body.mesh.tets.size());
  state.counters["largest_node_move_mm"] = 1e3 * largest_move;  // the deformation the spheres follow
  return packing;
}

// The naive peer of deform_spheres: each sphere its own SVD of its element's deformation gradient
// (the way before: deform_spheres takes F^T F's eigenvalues in closed form, once per element)
void deform_spheres_by_svd(const SoftBodyModel& body, const std::vector<Eigen::Vector3d>& x, std::vector<Sphere>& out) {
  for (std::size_t i = 0; i < body.spheres.size(); ++i) {
    const auto& e = body.spheres[i];
    const auto& t = body.mesh.tets[static_cast<std::size_t>(e.tet)];
    Eigen::Matrix3d now, rest;
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (int c = 0; c < 4; ++c) centre += e.weights[c] * x[static_cast<std::size_t>(t[static_cast<std::size_t>(c)])];
    for (int c = 0; c < 3; ++c) {
      const auto a = static_cast<std::size_t>(t[0]), b = static_cast<std::size_t>(t[static_cast<std::size_t>(c + 1)]);
      now.col(c) = x[b] - x[a];
      rest.col(c) = body.mesh.nodes[b] - body.mesh.nodes[a];
    }
    const Eigen::Matrix3d f = now * rest.inverse();
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(f);
    const Eigen::Vector3d sigmas = svd.singularValues();
    const double sigma = std::min({sigmas[0], sigmas[1], sigmas[2]});
    const double stretch = f.determinant() > 0.0 ? std::max(sigma, kMinSphereStretch) : kMinSphereStretch;
    out[i] = Sphere{static_cast<float>(centre.x()), static_cast<float>(centre.y()), static_cast<float>(centre.z()),
                    static_cast<float>(e.rest_radius * stretch)};
  }
}

// The packing riding along, per simulation step: every sphere moved with its tetrahedron and its
// radius scaled by its smallest stretch (deform_spheres, `deform`), the tree refitted bottom-up
// (SphereTree::refit, `refit`), or both (`step`); or the hierarchy regrouped over the moved
// spheres (collette::rebuild_sphere_tree, `rebuild`: what a step does instead of the refit when
// the tree is too distorted); items_per_second is spheres per second.
enum class RidePart { kDeform, kDeformBySvd, kRefit, kStep, kRebuild };
void run_riding_packing(benchmark::State& state, RidePart part) {
  auto packing = make_riding_packing(state, static_cast<int>(state.range(0)));
  if (!packing) return;
  if (part == RidePart::kRebuild) {
    deform_spheres(packing->body, packing->positions, packing->moved);
    packing->tree.refit(packing->moved);
  }
  for (auto _ : state) {
    if (part == RidePart::kDeformBySvd) deform_spheres_by_svd(packing->body, packing->positions, packing->moved);
    else if (part == RidePart::kDeform || part == RidePart::kStep) deform_spheres(packing->body, packing->positions, packing->moved);
    if (part == RidePart::kRefit || part == RidePart::kStep) packing->tree.refit(packing->moved);
    if (part == RidePart::kRebuild && !uh::collette::rebuild_sphere_tree(packing->tree)) state.SkipWithError("the rebuild failed");
    benchmark::DoNotOptimize(packing->moved.data());
    benchmark::DoNotOptimize(packing->tree.nodes().data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(packing->moved.size()));
}
void BM_SoftPackingDeform(benchmark::State& state) { run_riding_packing(state, RidePart::kDeform); }
void BM_SoftPackingDeformBySvd(benchmark::State& state) { run_riding_packing(state, RidePart::kDeformBySvd); }
void BM_SoftPackingRefit(benchmark::State& state) { run_riding_packing(state, RidePart::kRefit); }
void BM_SoftPackingStep(benchmark::State& state) { run_riding_packing(state, RidePart::kStep); }
void BM_SoftPackingRebuild(benchmark::State& state) { run_riding_packing(state, RidePart::kRebuild); }
BENCHMARK(BM_SoftPackingDeform)->Arg(1000)->Arg(10000)->Arg(50000)->Unit(benchmark::kMicrosecond)->MinTime(1.0);
BENCHMARK(BM_SoftPackingDeformBySvd)->Arg(1000)->Arg(10000)->Arg(50000)->Unit(benchmark::kMicrosecond)->MinTime(1.0);
BENCHMARK(BM_SoftPackingRefit)->Arg(1000)->Arg(10000)->Arg(50000)->Unit(benchmark::kMicrosecond)->MinTime(1.0);
BENCHMARK(BM_SoftPackingStep)->Arg(1000)->Arg(10000)->Arg(50000)->Unit(benchmark::kMicrosecond)->MinTime(1.0);
BENCHMARK(BM_SoftPackingRebuild)->Arg(1000)->Arg(10000)->Arg(50000)->Unit(benchmark::kMillisecond)->MinTime(1.0);

double heap_in_use_mb() {
  const struct mallinfo2 info = mallinfo2();
  return static_cast<double>(info.uordblks + info.hblkhd) / 1.0e6;
}

// The memory of a block's simulation: the heap its mesh, model and default solver hold after 20
// steps (glibc's count of bytes in use, before and after), and the process's peak resident set
// (getrusage's high-water mark, which covers the factorisations' temporaries; it is the whole
// process's: run one size per process, --benchmark_filter='SoftBlockMemory/5000$').
void BM_SoftBlockMemory(benchmark::State& state) {
  for (auto _ : state) {
    const double before = heap_in_use_mb();
    auto block = make_block(state, static_cast<int>(state.range(0)), {});
    if (!block) return;
    for (int step = 0; step < 20; ++step) block->advance();
    state.counters["held_mb"] = heap_in_use_mb() - before;
    state.counters["tets"] = static_cast<double>(block->fem().mesh().tets.size());
  }
  struct rusage usage {};
  getrusage(RUSAGE_SELF, &usage);
  state.counters["process_peak_rss_mb"] = static_cast<double>(usage.ru_maxrss) * 1024.0 / 1.0e6;  // ru_maxrss is in KiB
}
BENCHMARK(BM_SoftBlockMemory)->Arg(1000)->Arg(5000)->Arg(20000)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
BENCHMARK_MAIN();
