// Sphere-tree queries against FCL and Bullet on the same poses, in the same run.
//
// Scene (as in the shared peer figures): two copies of the 69,666-triangle bunny, B rotated
// 30 degrees about Y around its box centre and moved along X; "shallow" = 2 % of the x-extent past
// first contact, "deep" = 25 %; a small deterministic wobble per query. First contact is found by
// bisection with FCL's boolean query on the meshes. The 10,000 spheres are packed once and cached
// as a .ist file in the build directory; the tree over them is built anew at each start, so it is
// always the current builder's (build_sphere_tree() defaults).
//
// Counters per benchmark: median_us, p99_us, max_us per query; the FCL and Bullet rows also carry
// the ratio of their median to this module's volume-query median on the same case.
//
// Deep random poses (BM_DeepRandomPoses, `--benchmark_filter=DeepRandom`): B at kDeepPoses random
// orientations (fixed seed), each moved along its own random direction until the packings overlap
// by a quarter of the packing volume (bisection on the exact query's volume). Every iteration runs
// the volume query and FCL's all-contacts query on the same pose, one after the other (rotating
// which goes first), so both see the same machine load, and the query's reference path
// (`reference_kernel`: the scalar path before the SIMD kernels) on the same pose; each pose 10 times.
// Counters: median, p90 and max of both over all poses and repetitions, and the ratio of the medians.
// Each iteration also runs the query with the AVX2 kernels (`avx2_median_us`: `use_avx512` off),
// with the AVX-512 kernels where the CPU has them (`avx512_median_us`: `force_avx512`, which the
// default takes only on AMD's CPUs), with the baseline kernels (`sse2_median_us`: `use_avx2` off;
// `kernel_lanes` says which width the default took: 16 with AVX-512) and with its worker thread
// (`two_threads_*`, and how many of the frontier's chunks the worker ran per query); the seven run
// in a rotating order.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <btBulletCollisionCommon.h>
#include <BulletCollision/Gimpact/btGImpactCollisionAlgorithm.h>
#include <BulletCollision/Gimpact/btGImpactShape.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/geometry/bvh/BVH_model.h>

#include "uh/collette/ist_file.hpp"
#include "uh/collette/mesh_import.hpp"
#include "uh/collette/sphere_packing.hpp"
#include "uh/collette/sphere_tree_builder.hpp"
#include "uh/collette/time_critical_query.hpp"
#include "uh/collette/volume_query.hpp"
#include "uh/collette/distance_query.hpp"

namespace {

using namespace uh;
using namespace uh::collette;
using Clock = std::chrono::steady_clock;

constexpr int kSpheres = 10000;
constexpr int kWobblePoses = 64;
constexpr int kDeepPoses = 64;
constexpr double kDeepOverlapFraction = 0.25;  // of the packing volume

struct Scene {
  TriangleMesh mesh;
  SphereTree tree;
  Vec3 box_centre{};
  double extent_x = 0.0;
  double first_contact_x = 0.0;  // x-shift of B's box centre at first contact
  std::shared_ptr<fcl::BVHModel<fcl::OBBRSSd>> fcl_model;
  std::vector<Pose> poses[2];    // [shallow, deep] wobbled poses of B in A
  std::vector<Pose> deep_random;  // random orientations, a quarter of the packing volume overlapping
  std::vector<double> deep_random_fraction;  // the overlap fraction reached at each
};

fcl::Transform3d to_fcl(const Pose& p) {
  fcl::Transform3d t = fcl::Transform3d::Identity();
  t.linear() = Eigen::Quaterniond(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z).toRotationMatrix();
  t.translation() = Eigen::Vector3d(p.position.x, p.position.y, p.position.z);
  return t;
}

// B rotated by `rot` about its box centre, the centre then moved by `shift` from A's box centre.
Pose pose_of_b(const Scene& s, const Quat& rot, const Vec3& shift) {
  const Vec3 c = s.box_centre;
  return {rot, c + shift - rotate(rot, c)};
}

bool fcl_touching(const Scene& s, const Pose& b_in_a) {
  fcl::CollisionObjectd a(s.fcl_model, fcl::Transform3d::Identity());
  fcl::CollisionObjectd b(s.fcl_model, to_fcl(b_in_a));
  fcl::CollisionRequestd request;
  fcl::CollisionResultd result;
  fcl::collide(&a, &b, request, result);
  return result.isCollision();
}

Result<SphereTree> load_or_build_tree(const TriangleMesh& mesh, const std::filesystem::path& mesh_path) {
  const auto hash = [&]() -> std::uint64_t {
    std::FILE* f = std::fopen(mesh_path.c_str(), "rb");
    if (!f) return 0;
    std::vector<std::byte> bytes(std::filesystem::file_size(mesh_path));
    const std::size_t got = std::fread(bytes.data(), 1, bytes.size(), f);
    std::fclose(f);
    bytes.resize(got);
    return ist_hash_bytes(bytes);
  }();
  const std::filesystem::path cache = std::filesystem::path(UH_BENCH_CACHE_DIR) / "bunny_69k_10000_arity8.ist";
  if (auto cached = load_ist(cache); cached && cached->meta.source_mesh_hash == hash &&
                                     cached->tree.leaf_count() > 0 &&
                                     cached->tree.arity() == SphereTreeBuildOptions{}.arity) {
    // the hierarchy is the current builder's, whatever built the cached one
    return build_sphere_tree(cached->tree.leaves());
  }
  std::fprintf(stderr, "packing %d spheres into %s (cached afterwards in %s)...\n", kSpheres, mesh_path.c_str(), cache.c_str());
  PackingOptions options;
  options.target_sphere_count = kSpheres;
  auto packing = pack_spheres(mesh, options);
  if (!packing) return packing.error();
  auto tree = build_sphere_tree(packing->spheres);
  if (!tree) return tree.error();
  IstAsset asset{std::move(*tree), {}};
  asset.meta = {.meters_per_unit = 1.0, .source_mesh_hash = hash, .coverage = packing->report.coverage,
                .mesh_volume = packing->report.mesh_volume, .max_gap = packing->report.max_gap,
                .build_seconds = packing->report.build_seconds};
  std::fprintf(stderr, "packed: %lld spheres, coverage %.3f, max gap %.4g, %.1f s\n",
               static_cast<long long>(packing->report.sphere_count), packing->report.coverage, packing->report.max_gap,
               packing->report.build_seconds);
  if (const Status saved = save_ist(cache, asset); !saved) std::fprintf(stderr, "%s\n", saved.error().message.c_str());
  return std::move(asset.tree);
}

// A uniformly random rotation (Shoemake's method).
Quat random_rotation(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double u1 = u(rng), u2 = 2.0 * kPi * u(rng), u3 = 2.0 * kPi * u(rng);
  const double a = std::sqrt(1.0 - u1), b = std::sqrt(u1);
  return normalized(Quat{a * std::cos(u2), a * std::sin(u2), b * std::sin(u3), b * std::cos(u3)});
}

// Per random rotation, the shift along a random direction at which the packings overlap by
// kDeepOverlapFraction of their volume: the overlap is 1 at shift 0 for the identity rotation, but
// a rotated copy may overlap less than that fraction even centred; such rotations are redrawn.
void make_deep_random_poses(Scene& sc) {
  std::mt19937_64 rng(20261123);
  std::normal_distribution<double> gauss(0.0, 1.0);
  VolumeQuery query({.collect_pairs = false});
  const double packing_volume = sc.tree.total_volume();
  const auto fraction = [&](const Pose& p) {
    return query.run(sc.tree, sc.tree, p).total_volume / packing_volume;
  };
  const double reach = 2.0 * static_cast<double>(sc.tree.root().radius) + 1e-3;
  while (static_cast<int>(sc.deep_random.size()) < kDeepPoses) {
    const Quat rot = random_rotation(rng);
    const Vec3 dir = normalized(Vec3{gauss(rng), gauss(rng), gauss(rng)});
    if (fraction(pose_of_b(sc, rot, {})) < kDeepOverlapFraction) continue;
    double lo = 0.0, hi = reach;  // overlap above the target at lo, below it at hi
    for (int i = 0; i < 32; ++i) {
      const double mid = 0.5 * (lo + hi);
      (fraction(pose_of_b(sc, rot, mid * dir)) > kDeepOverlapFraction ? lo : hi) = mid;
    }
    const Pose p = pose_of_b(sc, rot, 0.5 * (lo + hi) * dir);
    sc.deep_random.push_back(p);
    sc.deep_random_fraction.push_back(fraction(p));
  }
}

const Scene& scene() {
  static const std::unique_ptr<Scene> s = [] {
    auto sc = std::make_unique<Scene>();
    const std::filesystem::path path = std::filesystem::path(UH_SHARED_ASSET_DIR) / "bunny_glmark2_69k.obj";
    auto mesh = load_mesh(path);
    if (!mesh) {
      std::fprintf(stderr, "%s\n", mesh.error().message.c_str());
      std::exit(1);
    }
    sc->mesh = std::move(*mesh);
    auto tree = load_or_build_tree(sc->mesh, path);
    if (!tree) {
      std::fprintf(stderr, "%s\n", tree.error().message.c_str());
      std::exit(1);
    }
    sc->tree = std::move(*tree);
    const Aabb box = mesh_bounds(sc->mesh);
    sc->box_centre = 0.5 * (box.min + box.max);
    sc->extent_x = box.max.x - box.min.x;

    std::vector<fcl::Vector3d> v;
    for (const Vec3& p : sc->mesh.vertices) v.emplace_back(p.x, p.y, p.z);
    std::vector<fcl::Triangle> t;
    for (const auto& f : sc->mesh.triangles)
      t.emplace_back(static_cast<std::size_t>(f[0]), static_cast<std::size_t>(f[1]), static_cast<std::size_t>(f[2]));
    sc->fcl_model = std::make_shared<fcl::BVHModel<fcl::OBBRSSd>>();
    sc->fcl_model->beginModel();
    sc->fcl_model->addSubModel(v, t);
    sc->fcl_model->endModel();

    // first contact along +x: bisection between touching (0) and apart (2 extents)
    const Quat rot = quat_from_axis_angle({0, 1, 0}, 30.0 * kPi / 180.0);
    double lo = 0.0, hi = 2.0 * sc->extent_x;
    for (int i = 0; i < 40; ++i) {
      const double mid = 0.5 * (lo + hi);
      (fcl_touching(*sc, pose_of_b(*sc, rot, {mid, 0, 0})) ? lo : hi) = mid;
    }
    sc->first_contact_x = hi;
    const double depth_fraction[2] = {0.02, 0.25};
    for (int c = 0; c < 2; ++c) {
      const double x = sc->first_contact_x - depth_fraction[c] * sc->extent_x;
      for (int k = 0; k < kWobblePoses; ++k) {
        // wobble: +-0.5 degree about a turning axis, +-0.2 % of the extent
        const double ph = 2.0 * kPi * k / kWobblePoses;
        const Quat wob = quat_from_axis_angle({std::cos(ph), 1.0, std::sin(ph)}, 0.5 * kPi / 180.0 * std::sin(3 * ph));
        const Vec3 dx{0.002 * sc->extent_x * std::sin(ph), 0.002 * sc->extent_x * std::cos(2 * ph), 0.0};
        sc->poses[c].push_back(pose_of_b(*sc, wob * rot, Vec3{x, 0, 0} + dx));
      }
    }
    make_deep_random_poses(*sc);
    std::fprintf(stderr, "scene: %zu triangles, %d spheres, %d nodes, depth %d, x-extent %.4g, first contact at x %.4g\n",
                 sc->mesh.triangles.size(), sc->tree.leaf_count(), sc->tree.node_count(), sc->tree.depth(), sc->extent_x,
                 sc->first_contact_x);
    return sc;
  }();
  return *s;
}

// quantile q of sorted times
double quantile(const std::vector<double>& sorted, double q) {
  return sorted.empty() ? 0.0
                        : sorted[std::min(sorted.size() - 1,
                                          static_cast<std::size_t>(q * static_cast<double>(sorted.size())))];
}

// per-query wall times -> counters; returns the median [s]
double report(benchmark::State& state, std::vector<double>& times) {
  if (times.empty()) return 0.0;
  std::sort(times.begin(), times.end());
  const double median = quantile(times, 0.5);
  state.counters["median_us"] = median * 1e6;
  state.counters["p99_us"] = quantile(times, 0.99) * 1e6;
  state.counters["max_us"] = times.back() * 1e6;
  return median;
}

std::map<std::string, double> g_ist_median;  // case name -> volume query median [s]
const char* case_name(int c) { return c == 0 ? "shallow" : "deep"; }

void BM_IstVolumeQuery(benchmark::State& state) {
  const Scene& s = scene();
  const int c = static_cast<int>(state.range(0));
  const bool collect = state.range(1) != 0;
  VolumeQuery query({.collect_pairs = collect});
  std::vector<double> times;
  times.reserve(1 << 16);
  std::size_t k = 0;
  VolumeQueryResult last{};
  for (auto _ : state) {
    const Pose& p = s.poses[c][k++ % kWobblePoses];
    const auto t0 = Clock::now();
    last = query.run(s.tree, s.tree, p);
    const double dt = std::chrono::duration<double>(Clock::now() - t0).count();
    benchmark::DoNotOptimize(last);
    state.SetIterationTime(dt);
    times.push_back(dt);
  }
  const double median = report(state, times);
  if (collect) g_ist_median[case_name(c)] = median;
  state.counters["overlapping_pairs"] = static_cast<double>(last.stats.overlapping_pairs);
  state.counters["node_pairs"] = static_cast<double>(last.stats.node_pairs_visited);
  state.counters["leaf_tests"] = static_cast<double>(last.stats.leaf_pairs_tested);
  state.counters["volume"] = last.total_volume;
  state.SetLabel(std::string(case_name(c)) + (collect ? " pairs+totals" : " totals only"));
}
BENCHMARK(BM_IstVolumeQuery)->ArgsProduct({{0, 1}, {1, 0}})->UseManualTime()->Unit(benchmark::kMicrosecond)->MinTime(2.0);

void BM_IstTimeCriticalQuery(benchmark::State& state) {
  const Scene& s = scene();
  const int c = static_cast<int>(state.range(0));
  const std::int64_t budget = state.range(1);
  TimeCriticalQuery query;
  VolumeQuery exact({.collect_pairs = false});
  std::vector<double> times;
  times.reserve(1 << 16);
  double err_sum = 0.0;
  std::size_t k = 0;
  for (auto _ : state) {
    const Pose& p = s.poses[c][k % kWobblePoses];
    const auto t0 = Clock::now();
    const TimeCriticalResult& r = query.run(s.tree, s.tree, p, {.max_expansions = budget});
    const double dt = std::chrono::duration<double>(Clock::now() - t0).count();
    state.SetIterationTime(dt);
    times.push_back(dt);
    if (k < kWobblePoses) {
      const double e = exact.run(s.tree, s.tree, p).total_volume;
      err_sum += std::abs(r.volume_estimate - e) / e;
    }
    ++k;
  }
  report(state, times);
  state.counters["rel_volume_error"] = err_sum / static_cast<double>(std::min<std::size_t>(k, kWobblePoses));
  state.SetLabel(std::string(case_name(c)) + " budget " + std::to_string(budget) + " expansions");
}
BENCHMARK(BM_IstTimeCriticalQuery)
    ->ArgsProduct({{1}, {500, 2000, 8000}})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond)
    ->MinTime(1.0);

void BM_IstDistanceQuery(benchmark::State& state) {
  const Scene& s = scene();
  const bool warm = state.range(0) != 0;
  DistanceQuery query({.warm_start = warm});
  // apart by 5 % of the extent, with the wobble
  std::vector<Pose> poses;
  const Quat rot = quat_from_axis_angle({0, 1, 0}, 30.0 * kPi / 180.0);
  for (int k = 0; k < kWobblePoses; ++k) {
    const double ph = 2.0 * kPi * k / kWobblePoses;
    poses.push_back(pose_of_b(s, rot, {s.first_contact_x + s.extent_x * (0.05 + 0.002 * std::sin(ph)), 0.0, 0.0}));
  }
  std::vector<double> times;
  std::size_t k = 0;
  double d = 0.0;
  for (auto _ : state) {
    const auto t0 = Clock::now();
    d = query.run(s.tree, s.tree, poses[k++ % kWobblePoses]).distance;
    const double dt = std::chrono::duration<double>(Clock::now() - t0).count();
    state.SetIterationTime(dt);
    times.push_back(dt);
  }
  report(state, times);
  state.counters["distance_over_extent"] = d / s.extent_x;
  state.SetLabel(warm ? "apart 5% warm start" : "apart 5% cold");
}
BENCHMARK(BM_IstDistanceQuery)->Arg(0)->Arg(1)->UseManualTime()->Unit(benchmark::kMicrosecond)->MinTime(1.0);

// Frame-to-frame coherence on a moving deep contact: B circles around the deep pose (radius 1 % of
// the extent) while turning, `step` (in 1e-4 of the x-extent) per query for B's farthest point, as
// a tool moving at steady speed between collision frames. Arg 0: the step; arg 1: the skin in 1e-4
// of the extent. Every iteration runs a plain traversal and the coherent query on the same pose,
// one right after the other (alternating which goes first), so both see the same machine load;
// the manual time is the coherent query's, and the counters give both and their ratios, plus the
// number of poses where the two disagreed (must be 0).
void BM_IstVolumeQueryMoving(benchmark::State& state) {
  const Scene& s = scene();
  const std::int64_t step_arg = state.range(0), skin_arg = state.range(1);
  const double step = 1e-4 * static_cast<double>(step_arg) * s.extent_x;
  const float skin = static_cast<float>(1e-4 * static_cast<double>(skin_arg) * s.extent_x);
  VolumeQuery plain;
  VolumeQuery coherent({.coherence_skin = skin});
  const Pose base = s.poses[1][0];
  const double radius = 0.01 * s.extent_x;
  const double reach = static_cast<double>(s.tree.root().radius);
  // per query: an arc of step / 2 along the circle, and a turn moving the farthest point step / 2
  const double arc = 0.5 * step / radius, turn = 0.5 * step / reach;
  std::vector<double> times_plain, times_coherent;
  times_plain.reserve(1 << 16);
  times_coherent.reserve(1 << 16);
  std::int64_t k = 0, reused = 0, candidates = 0, pairs = 0, mismatches = 0;
  for (auto _ : state) {
    const double ph = arc * static_cast<double>(k);
    const Quat spin = quat_from_axis_angle(normalized(Vec3{0.3, 1.0, 0.2}), 0.02 * std::sin(turn * static_cast<double>(k) / 0.02));
    const Pose p{normalized(spin * base.rotation), base.position + radius * Vec3{std::cos(ph) - 1.0, std::sin(ph), 0.0}};
    double dt_plain = 0.0, dt_coherent = 0.0;
    const auto timed = [&p, &s](VolumeQuery& q, double& dt) -> const VolumeQueryResult& {
      const auto t0 = Clock::now();
      const VolumeQueryResult& r = q.run(s.tree, s.tree, p);
      dt = std::chrono::duration<double>(Clock::now() - t0).count();
      return r;
    };
    if (k % 2 == 0) {
      timed(plain, dt_plain);
      timed(coherent, dt_coherent);
    } else {
      timed(coherent, dt_coherent);
      timed(plain, dt_plain);
    }
    const VolumeQueryResult& rp = plain.result();
    const VolumeQueryResult& rc = coherent.result();
    benchmark::DoNotOptimize(rc.total_volume);
    if (rp.stats.overlapping_pairs != rc.stats.overlapping_pairs ||
        std::abs(rp.total_volume - rc.total_volume) > 1e-9 * rp.total_volume)
      ++mismatches;
    state.SetIterationTime(dt_coherent);
    times_plain.push_back(dt_plain);
    times_coherent.push_back(dt_coherent);
    reused += rc.reused_candidates ? 1 : 0;
    candidates += rc.candidate_pairs;
    pairs += rc.stats.overlapping_pairs;
    ++k;
  }
  const auto mean_of = [](const std::vector<double>& t) {
    double sum = 0.0;
    for (const double x : t) sum += x;
    return sum / static_cast<double>(std::max<std::size_t>(1, t.size()));
  };
  const double mean_plain = mean_of(times_plain), mean_coherent = mean_of(times_coherent);
  std::sort(times_plain.begin(), times_plain.end());
  const double median_plain = times_plain.empty() ? 0.0 : times_plain[times_plain.size() / 2];
  const double max_plain = times_plain.empty() ? 0.0 : times_plain.back();
  const double median_coherent = report(state, times_coherent);
  const double n = static_cast<double>(std::max<std::int64_t>(1, k));
  state.counters["mean_us"] = mean_coherent * 1e6;
  state.counters["plain_mean_us"] = mean_plain * 1e6;
  state.counters["plain_median_us"] = median_plain * 1e6;
  state.counters["plain_max_us"] = max_plain * 1e6;
  state.counters["speedup_mean"] = mean_coherent > 0.0 ? mean_plain / mean_coherent : 0.0;
  state.counters["speedup_median"] = median_coherent > 0.0 ? median_plain / median_coherent : 0.0;
  state.counters["reused_fraction"] = static_cast<double>(reused) / n;
  state.counters["candidate_pairs"] = static_cast<double>(candidates) / n;
  state.counters["overlapping_pairs"] = static_cast<double>(pairs) / n;
  state.counters["mismatches"] = static_cast<double>(mismatches);
  state.SetLabel("deep, moving " + std::to_string(step_arg) + "e-4 extent/query, skin " + std::to_string(skin_arg) + "e-4 extent");
}
BENCHMARK(BM_IstVolumeQueryMoving)
    ->ArgsProduct({{5, 20, 50}, {25, 50, 100, 200}})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond)
    ->MinTime(1.0);

void BM_FclMeshMesh(benchmark::State& state) {
  const Scene& s = scene();
  const int c = static_cast<int>(state.range(0));
  const bool all = state.range(1) != 0;
  fcl::CollisionObjectd a(s.fcl_model, fcl::Transform3d::Identity());
  fcl::CollisionObjectd b(s.fcl_model, fcl::Transform3d::Identity());
  fcl::CollisionRequestd request(all ? 1000000 : 1, all);
  std::vector<double> times;
  std::size_t k = 0;
  std::size_t contacts = 0;
  for (auto _ : state) {
    b.setTransform(to_fcl(s.poses[c][k++ % kWobblePoses]));
    fcl::CollisionResultd result;
    const auto t0 = Clock::now();
    fcl::collide(&a, &b, request, result);
    const double dt = std::chrono::duration<double>(Clock::now() - t0).count();
    contacts = result.numContacts();
    state.SetIterationTime(dt);
    times.push_back(dt);
  }
  const double median = report(state, times);
  state.counters["contacts"] = static_cast<double>(contacts);
  if (all && g_ist_median.count(case_name(c)) && g_ist_median[case_name(c)] > 0.0)
    state.counters["ratio_fcl_over_ist"] = median / g_ist_median[case_name(c)];
  state.SetLabel(std::string(case_name(c)) + (all ? " all contacts" : " boolean"));
}
BENCHMARK(BM_FclMeshMesh)->ArgsProduct({{0, 1}, {1, 0}})->UseManualTime()->Unit(benchmark::kMicrosecond)->MinTime(1.0);

// The deep random poses: our volume query (pairs + totals) and FCL's all-contacts query on the
// same pose in each iteration (and the other paths of ours); the manual time is ours.
void BM_DeepRandomPoses(benchmark::State& state) {
  const Scene& s = scene();
  VolumeQuery query;
  VolumeQuery reference({.reference_kernel = true});
  VolumeQuery baseline({.use_avx2 = false});
  VolumeQuery avx2_only({.use_avx512 = false});
  VolumeQuery avx512_forced({.force_avx512 = true});
  VolumeQuery shared({.worker_thread = true});
  fcl::CollisionObjectd a(s.fcl_model, fcl::Transform3d::Identity());
  fcl::CollisionObjectd b(s.fcl_model, fcl::Transform3d::Identity());
  const fcl::CollisionRequestd request(1000000, true);
  std::vector<double> ours, reference_times, fcl_times, baseline_times, avx2_times, avx512_times, shared_times;
  ours.reserve(1 << 14);
  avx2_times.reserve(1 << 14);
  avx512_times.reserve(1 << 14);
  baseline_times.reserve(1 << 14);
  shared_times.reserve(1 << 14);
  double worker_chunks = 0.0;
  reference_times.reserve(1 << 14);
  fcl_times.reserve(1 << 14);
  std::int64_t mismatches = 0;
  std::size_t k = 0;
  double pairs = 0.0, node_pairs = 0.0, leaf_tests = 0.0, contacts = 0.0;
  std::int64_t pairs_min = std::numeric_limits<std::int64_t>::max(), pairs_max = 0;
  for (auto _ : state) {
    const Pose& p = s.deep_random[k % s.deep_random.size()];
    const auto run_ours = [&] {
      const auto t0 = Clock::now();
      const VolumeQueryResult& r = query.run(s.tree, s.tree, p);
      ours.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
      benchmark::DoNotOptimize(r.total_volume);
      pairs += static_cast<double>(r.stats.overlapping_pairs);
      pairs_min = std::min(pairs_min, r.stats.overlapping_pairs);
      pairs_max = std::max(pairs_max, r.stats.overlapping_pairs);
      node_pairs += static_cast<double>(r.stats.node_pairs_visited);
      leaf_tests += static_cast<double>(r.stats.leaf_pairs_tested);
    };
    const auto run_reference = [&] {
      const auto t0 = Clock::now();
      const VolumeQueryResult& r = reference.run(s.tree, s.tree, p);
      reference_times.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
      benchmark::DoNotOptimize(r.total_volume);
    };
    const auto run_other = [&](VolumeQuery& q, std::vector<double>& times) {
      const auto t0 = Clock::now();
      const VolumeQueryResult& r = q.run(s.tree, s.tree, p);
      times.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
      benchmark::DoNotOptimize(r.total_volume);
    };
    const auto run_fcl = [&] {
      b.setTransform(to_fcl(p));
      fcl::CollisionResultd result;
      const auto t0 = Clock::now();
      fcl::collide(&a, &b, request, result);
      fcl_times.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
      contacts += static_cast<double>(result.numContacts());
    };
    // all seven on the same pose, in an order that rotates, so that each sees the same load and
    // the same share of caches warmed by the one before
    const std::function<void()> runs[7] = {run_ours,
                                           run_reference,
                                           run_fcl,
                                           [&] { run_other(baseline, baseline_times); },
                                           [&] { run_other(avx2_only, avx2_times); },
                                           [&] { run_other(avx512_forced, avx512_times); },
                                           [&] { run_other(shared, shared_times); }};
    for (std::size_t i = 0; i < 7; ++i) runs[(k + i) % 7]();
    worker_chunks += shared.worker_chunks();
    // the fast path (each kernel width, one or two threads) must give exactly the reference path's
    // totals and pairs
    for (const VolumeQuery* q : {&query, &baseline, &avx2_only, &avx512_forced, &shared})
      if (q->result().total_volume != reference.result().total_volume ||
          q->result().pair_count != reference.result().pair_count)
        ++mismatches;
    state.SetIterationTime(ours.back());
    ++k;
  }
  const double n = static_cast<double>(std::max<std::size_t>(1, k));
  std::sort(ours.begin(), ours.end());
  std::sort(fcl_times.begin(), fcl_times.end());
  std::sort(reference_times.begin(), reference_times.end());
  std::sort(baseline_times.begin(), baseline_times.end());
  std::sort(avx2_times.begin(), avx2_times.end());
  std::sort(avx512_times.begin(), avx512_times.end());
  std::sort(shared_times.begin(), shared_times.end());
  state.counters["reference_median_us"] = quantile(reference_times, 0.5) * 1e6;
  state.counters["sse2_median_us"] = quantile(baseline_times, 0.5) * 1e6;
  state.counters["avx2_median_us"] = quantile(avx2_times, 0.5) * 1e6;
  state.counters["avx512_median_us"] = quantile(avx512_times, 0.5) * 1e6;
  state.counters["two_threads_median_us"] = quantile(shared_times, 0.5) * 1e6;
  state.counters["two_threads_p90_us"] = quantile(shared_times, 0.9) * 1e6;
  state.counters["two_threads_worker_chunks"] = worker_chunks / n;
  state.counters["kernel_lanes"] = query.kernel_lanes();
  state.counters["reference_p90_us"] = quantile(reference_times, 0.9) * 1e6;
  state.counters["mismatches"] = static_cast<double>(mismatches);
  state.counters["median_us"] = quantile(ours, 0.5) * 1e6;
  state.counters["p90_us"] = quantile(ours, 0.9) * 1e6;
  state.counters["max_us"] = ours.empty() ? 0.0 : ours.back() * 1e6;
  state.counters["fcl_median_us"] = quantile(fcl_times, 0.5) * 1e6;
  state.counters["fcl_p90_us"] = quantile(fcl_times, 0.9) * 1e6;
  state.counters["fcl_max_us"] = fcl_times.empty() ? 0.0 : fcl_times.back() * 1e6;
  state.counters["ratio_fcl_over_ist"] =
      quantile(ours, 0.5) > 0.0 ? quantile(fcl_times, 0.5) / quantile(ours, 0.5) : 0.0;
  state.counters["overlapping_pairs"] = pairs / n;
  state.counters["overlapping_pairs_min"] = static_cast<double>(pairs_min);
  state.counters["overlapping_pairs_max"] = static_cast<double>(pairs_max);
  state.counters["node_pairs"] = node_pairs / n;
  state.counters["leaf_tests"] = leaf_tests / n;
  state.counters["fcl_contacts"] = contacts / n;
  const auto [lo, hi] = std::minmax_element(s.deep_random_fraction.begin(), s.deep_random_fraction.end());
  state.counters["overlap_fraction_min"] = *lo;
  state.counters["overlap_fraction_max"] = *hi;
  state.SetLabel(std::to_string(s.deep_random.size()) +
                 " random orientations, a quarter of the volume overlapping");
}
BENCHMARK(BM_DeepRandomPoses)->Iterations(10 * kDeepPoses)->UseManualTime()->Unit(benchmark::kMicrosecond);

// Our query alone on the deep random poses (for profiling: `perf record` on this filter sees no FCL).
void BM_IstVolumeQueryDeepRandom(benchmark::State& state) {
  const Scene& s = scene();
  VolumeQuery query;
  std::vector<double> times;
  times.reserve(1 << 16);
  std::size_t k = 0;
  for (auto _ : state) {
    const auto t0 = Clock::now();
    const VolumeQueryResult& r = query.run(s.tree, s.tree, s.deep_random[k++ % s.deep_random.size()]);
    const double dt = std::chrono::duration<double>(Clock::now() - t0).count();
    benchmark::DoNotOptimize(r.total_volume);
    state.SetIterationTime(dt);
    times.push_back(dt);
  }
  report(state, times);
  state.SetLabel("deep random orientations, ours alone");
}
BENCHMARK(BM_IstVolumeQueryDeepRandom)->UseManualTime()->Unit(benchmark::kMicrosecond)->MinTime(2.0);

struct CountContacts : btCollisionWorld::ContactResultCallback {
  int count = 0;
  btScalar addSingleResult(btManifoldPoint&, const btCollisionObjectWrapper*, int, int, const btCollisionObjectWrapper*, int,
                           int) override {
    ++count;
    return 0;
  }
};

void BM_BulletGImpact(benchmark::State& state) {
  const Scene& s = scene();
  const int c = static_cast<int>(state.range(0));
  std::vector<btScalar> verts;
  for (const Vec3& p : s.mesh.vertices) {
    verts.push_back(static_cast<btScalar>(p.x));
    verts.push_back(static_cast<btScalar>(p.y));
    verts.push_back(static_cast<btScalar>(p.z));
  }
  std::vector<int> idx;
  for (const auto& f : s.mesh.triangles) idx.insert(idx.end(), {f[0], f[1], f[2]});
  btTriangleIndexVertexArray array(static_cast<int>(s.mesh.triangles.size()), idx.data(), 3 * static_cast<int>(sizeof(int)),
                                   static_cast<int>(s.mesh.vertices.size()), verts.data(), 3 * static_cast<int>(sizeof(btScalar)));
  btGImpactMeshShape shape(&array);
  shape.updateBound();
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher(&config);
  btGImpactCollisionAlgorithm::registerAlgorithm(&dispatcher);
  // without a closest-points function for GImpact, contactPairTest finds nothing
  static btGImpactCollisionAlgorithm::CreateFunc gimpact_cf;
  for (int i = 0; i < MAX_BROADPHASE_COLLISION_TYPES; ++i) {
    dispatcher.registerClosestPointsCreateFunc(GIMPACT_SHAPE_PROXYTYPE, i, &gimpact_cf);
    dispatcher.registerClosestPointsCreateFunc(i, GIMPACT_SHAPE_PROXYTYPE, &gimpact_cf);
  }
  btDbvtBroadphase broadphase;
  btCollisionWorld world(&dispatcher, &broadphase, &config);
  btCollisionObject a, b;
  a.setCollisionShape(&shape);
  b.setCollisionShape(&shape);
  auto to_bt = [](const Pose& p) {
    btTransform t;
    t.setRotation(btQuaternion(static_cast<btScalar>(p.rotation.x), static_cast<btScalar>(p.rotation.y),
                               static_cast<btScalar>(p.rotation.z), static_cast<btScalar>(p.rotation.w)));
    t.setOrigin(btVector3(static_cast<btScalar>(p.position.x), static_cast<btScalar>(p.position.y),
                          static_cast<btScalar>(p.position.z)));
    return t;
  };
  a.setWorldTransform(to_bt(Pose{}));
  std::vector<double> times;
  std::size_t k = 0;
  int contacts = 0;
  for (auto _ : state) {
    b.setWorldTransform(to_bt(s.poses[c][k++ % kWobblePoses]));
    CountContacts cb;
    const auto t0 = Clock::now();
    world.contactPairTest(&a, &b, cb);
    const double dt = std::chrono::duration<double>(Clock::now() - t0).count();
    contacts = cb.count;
    state.SetIterationTime(dt);
    times.push_back(dt);
  }
  const double median = report(state, times);
  state.counters["contacts"] = contacts;
  if (g_ist_median.count(case_name(c)) && g_ist_median[case_name(c)] > 0.0)
    state.counters["ratio_bullet_over_ist"] = median / g_ist_median[case_name(c)];
  state.SetLabel(std::string(case_name(c)) + " contactPairTest");
}
BENCHMARK(BM_BulletGImpact)->Arg(0)->Arg(1)->UseManualTime()->Unit(benchmark::kMicrosecond)->MinTime(1.0);

}  // namespace

BENCHMARK_MAIN();
