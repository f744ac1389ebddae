// Sphere packing benchmarks: the 69,666-triangle bunny from the shared assets with 10,000
// spheres (the project's target: under 5 s, coverage >= 85%), and coverage against sphere count.
// Run: uh_collette_packing_bench --benchmark_counters_tabular=true

#include <benchmark/benchmark.h>

#include <filesystem>
#include <string>

#include "uh/collette/mesh_import.hpp"
#include "uh/collette/sphere_packing.hpp"

namespace {

using uh::collette::TriangleMesh;

const uh::Result<TriangleMesh>& shared_bunny() {
  static const uh::Result<TriangleMesh> mesh = [] {
    const std::filesystem::path path = std::filesystem::path(UH_SHARED_ASSET_DIR) / "bunny_glmark2_69k.obj";
    if (!std::filesystem::exists(path)) {
      return uh::Result<TriangleMesh>(uh::Error{"skipped: " + path.string() + " is absent (shared assets not installed)"});
    }
    return uh::collette::load_mesh(path);
  }();
  return mesh;
}

const uh::Result<TriangleMesh>& repo_bunny() {
  static const uh::Result<TriangleMesh> mesh =
      uh::collette::load_mesh(std::filesystem::path(UH_ASSET_DIR) / "meshes" / "bunny_npm_3674.obj");
  return mesh;
}

void pack(benchmark::State& state, const uh::Result<TriangleMesh>& mesh, std::int64_t count) {
  if (!mesh) {
    state.SkipWithError(mesh.error().message.c_str());
    return;
  }
  uh::collette::PackingReport report{};
  for (auto _ : state) {
    auto packing = uh::collette::pack_spheres(*mesh, {.target_sphere_count = count});
    if (!packing) {
      state.SkipWithError(packing.error().message.c_str());
      return;
    }
    report = packing->report;
    benchmark::DoNotOptimize(packing->spheres.data());
  }
  state.counters["spheres"] = static_cast<double>(report.sphere_count);
  state.counters["build_s"] = report.build_seconds;
  state.counters["coverage"] = report.coverage;
  state.counters["max_gap"] = report.max_gap;
  state.counters["gap_rel"] = report.max_gap / std::cbrt(report.mesh_volume);
  state.counters["voxel"] = report.voxel_size;
  state.counters["voxels"] = static_cast<double>(report.voxel_count);
  state.counters["r_min"] = report.min_radius;
}

void BM_PackBunny69k_10000(benchmark::State& state) { pack(state, shared_bunny(), 10000); }
BENCHMARK(BM_PackBunny69k_10000)->Unit(benchmark::kSecond)->Iterations(1)->Repetitions(3)->ReportAggregatesOnly(false);

void BM_PackBunny69k_Coverage(benchmark::State& state) { pack(state, shared_bunny(), state.range(0)); }
BENCHMARK(BM_PackBunny69k_Coverage)
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->Arg(70)
    ->Arg(670)
    ->Arg(2000)
    ->Arg(5000)
    ->Arg(10000)
    ->Arg(20000);

void BM_PackBunny3674(benchmark::State& state) { pack(state, repo_bunny(), state.range(0)); }
BENCHMARK(BM_PackBunny3674)->Unit(benchmark::kMillisecond)->Arg(1000)->Arg(10000);

}  // namespace

BENCHMARK_MAIN();
