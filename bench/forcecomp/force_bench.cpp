// Cost of the force stage per haptic tick: the penalty law over a pair list, the multi-rate
// re-evaluation of a held pair set, the local wrench model (built per frame, rendered per tick),
// and the safety stage.

#include <benchmark/benchmark.h>

#include <memory>
#include <random>
#include <vector>

#include "uh/core/sphere_overlap.hpp"
#include "uh/forcecomp/force_component.hpp"
#include "uh/forcecomp/force_safety.hpp"
#include "uh/forcecomp/held_contact_set.hpp"
#include "uh/forcecomp/wrench_model.hpp"

namespace {

using namespace uh;
using namespace uh::forcecomp;

// `count` overlapping leaf pairs between two packings, as a volume query would report them
std::vector<SpherePairContact> make_pairs(int count, const Pose& world_from_a, const Pose& world_from_b) {
  std::mt19937 rng(1234);
  std::uniform_real_distribution<float> pos(-0.05f, 0.05f);
  std::uniform_real_distribution<float> rad(0.002f, 0.006f);
  std::uniform_real_distribution<float> off(0.3f, 0.95f);
  std::vector<SpherePairContact> pairs;
  pairs.reserve(static_cast<std::size_t>(count));
  const Pose b_from_world = inverse(world_from_b);
  while (static_cast<int>(pairs.size()) < count) {
    SpherePairContact p;
    p.sphere_a_local = {pos(rng), pos(rng), pos(rng), rad(rng)};
    const Vec3 a_local{static_cast<double>(p.sphere_a_local.x), static_cast<double>(p.sphere_a_local.y),
                       static_cast<double>(p.sphere_a_local.z)};
    const Vec3 ca = transform_point(world_from_a, a_local);
    const float rb = rad(rng);
    const double dist = static_cast<double>(off(rng) * (p.sphere_a_local.radius + rb));
    const Vec3 dir = normalized(Vec3{static_cast<double>(pos(rng)), static_cast<double>(pos(rng)), 0.05});
    const Vec3 cb = ca + dist * dir;
    const Vec3 cb_local = transform_point(b_from_world, cb);
    p.sphere_b_local = {static_cast<float>(cb_local.x), static_cast<float>(cb_local.y), static_cast<float>(cb_local.z), rb};
    const double ra = static_cast<double>(p.sphere_a_local.radius);
    const SphereOverlap<double> o = sphere_overlap(dist, ra, static_cast<double>(rb));
    const Vec3 c = ca + o.centroid_offset * dir;
    p.volume = static_cast<float>(o.volume);
    p.area = static_cast<float>(o.area);
    p.normal_world[0] = static_cast<float>(dir.x);
    p.normal_world[1] = static_cast<float>(dir.y);
    p.normal_world[2] = static_cast<float>(dir.z);
    p.centroid_world[0] = static_cast<float>(c.x);
    p.centroid_world[1] = static_cast<float>(c.y);
    p.centroid_world[2] = static_cast<float>(c.z);
    pairs.push_back(p);
  }
  return pairs;
}

ForceComponent make_tool(ForceMode mode) {
  ForceComponentOptions o;
  o.params.stiffness = 2e4;  // the default (gradient) law
  o.params.damping = 2.0;
  o.mode = mode;
  return ForceComponent(o);
}

void BM_EvaluatePenalty(benchmark::State& state, ForceMode mode) {
  const Pose wa{};
  const Pose wb{quat_from_axis_angle({0, 1, 0}, 0.3), {0.01, 0, 0.02}};
  const auto pairs = make_pairs(static_cast<int>(state.range(0)), wa, wb);
  const ForceComponent tool = make_tool(mode);
  const BodyMotion self = tool.body_motion(wb, {0.01, 0, -0.02}, {0.1, 0, 0});
  for (auto _ : state) {
    const PenaltyResult r = tool.evaluate(pairs, self);
    benchmark::DoNotOptimize(r);
  }
  state.counters["pairs"] = static_cast<double>(pairs.size());
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK_CAPTURE(BM_EvaluatePenalty, six_dof, ForceMode::k6Dof)->Arg(100)->Arg(1000)->Arg(10000);
BENCHMARK_CAPTURE(BM_EvaluatePenalty, three_dof, ForceMode::k3Dof)->Arg(100)->Arg(1000)->Arg(10000);

// multi-rate: recompute lens volumes, normals and centroids of the held pairs at a new pose, then
// the force; this is what the haptic thread does every tick between collision results
void BM_HeldReevaluateAndForce(benchmark::State& state) {
  const Pose wa{};
  const Pose wb{quat_from_axis_angle({0, 1, 0}, 0.3), {0.01, 0, 0.02}};
  const auto pairs = make_pairs(static_cast<int>(state.range(0)), wa, wb);
  HeldContactSet held(static_cast<std::int32_t>(pairs.size()));
  held.hold(pairs, 1, 0.0);
  const ForceComponent tool = make_tool(ForceMode::k6Dof);
  Pose moving = wb;
  int k = 0;
  for (auto _ : state) {
    // a hand moving by about a micrometre per tick
    moving.position.z = wb.position.z + 1e-6 * static_cast<double>(k++ % 100);
    const BodyMotion self = tool.body_motion(moving, {0, 0, 0.001}, {});
    const PenaltyResult r = tool.evaluate(held, wa, moving, self);
    benchmark::DoNotOptimize(r);
  }
  state.counters["pairs"] = static_cast<double>(pairs.size());
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_HeldReevaluateAndForce)->Arg(100)->Arg(1000)->Arg(10000)->Arg(17000);

// the local wrench model: built once per collision frame on the collision thread (O(pairs)) ...
void BM_WrenchModelBuild(benchmark::State& state) {
  const Pose wa{};
  const Pose wb{quat_from_axis_angle({0, 1, 0}, 0.3), {0.01, 0, 0.02}};
  const auto pairs = make_pairs(static_cast<int>(state.range(0)), wa, wb);
  const ForceComponent tool = make_tool(ForceMode::k6Dof);
  const PenaltyInput in = tool.penalty_input(tool.body_motion(wb, {}, {}), {});
  for (auto _ : state) {
    const WrenchModel m = build_wrench_model(pairs, wa, wb, in);
    benchmark::DoNotOptimize(m);
  }
  state.counters["pairs"] = static_cast<double>(pairs.size());
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_WrenchModelBuild)->Arg(100)->Arg(1000)->Arg(10000)->Arg(17000);

// ... and rendered every haptic tick (O(1): the pair count only changes the numbers in the model),
// with a new model every fourth tick as from a 250 Hz collision thread at 1 kHz
void BM_WrenchModelRender(benchmark::State& state) {
  const Pose wa{};
  const Pose wb{quat_from_axis_angle({0, 1, 0}, 0.3), {0.01, 0, 0.02}};
  const auto pairs = make_pairs(static_cast<int>(state.range(0)), wa, wb);
  const ForceComponent tool = make_tool(ForceMode::k6Dof);
  WrenchModel model = build_wrench_model(pairs, wa, wb, tool.penalty_input(tool.body_motion(wb, {}, {}), {}));
  WrenchModelRenderer renderer;
  Pose moving = wb;
  int k = 0;
  for (auto _ : state) {
    if (k % 4 == 0) {
      model.time_s = 0.001 * k;
      renderer.take(model);
    }
    moving.position.z = wb.position.z + 1e-6 * static_cast<double>(k % 100);
    const BodyMotion self = tool.body_motion(moving, {0, 0, 0.001}, {});
    const Wrench w = renderer.render(0.001 * k++, moving.rotation, self);
    benchmark::DoNotOptimize(w);
  }
  state.counters["pairs"] = static_cast<double>(pairs.size());
}
BENCHMARK(BM_WrenchModelRender)->Arg(100)->Arg(17000);

// the same through the two-step reference path (reevaluate() writes world-frame pairs, then the
// law runs over them), to show what the fused evaluation saves
void BM_HeldReevaluateThenPenalty(benchmark::State& state) {
  const Pose wa{};
  const Pose wb{quat_from_axis_angle({0, 1, 0}, 0.3), {0.01, 0, 0.02}};
  const auto pairs = make_pairs(static_cast<int>(state.range(0)), wa, wb);
  HeldContactSet held(static_cast<std::int32_t>(pairs.size()));
  held.hold(pairs, 1, 0.0);
  const ForceComponent tool = make_tool(ForceMode::k6Dof);
  Pose moving = wb;
  int k = 0;
  for (auto _ : state) {
    moving.position.z = wb.position.z + 1e-6 * static_cast<double>(k++ % 100);
    const BodyMotion self = tool.body_motion(moving, {0, 0, 0.001}, {});
    const PenaltyResult r = evaluate_penalty(held.reevaluate(wa, moving), tool.penalty_input(self, {}));
    benchmark::DoNotOptimize(r);
  }
  state.counters["pairs"] = static_cast<double>(pairs.size());
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_HeldReevaluateThenPenalty)->Arg(100)->Arg(1000)->Arg(10000);

// holding a collision result (once per collision frame): a view, no copy
void BM_HeldHold(benchmark::State& state) {
  const auto pairs = make_pairs(static_cast<int>(state.range(0)), Pose{}, Pose{});
  HeldContactSet held(static_cast<std::int32_t>(pairs.size()));
  std::uint64_t seq = 0;
  for (auto _ : state) {
    held.hold(pairs, ++seq, 0.0);
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_HeldHold)->Arg(100)->Arg(1000)->Arg(10000);

void BM_ForceSafetyApply(benchmark::State& state) {
  ForceSafety safety;
  double t = 0.0;
  for (auto _ : state) {
    t += 0.001;
    const Wrench w = safety.apply(Wrench{{3.0, 20.0, -1.0}, {0.1, 0.9, 0.0}}, t, t - 0.005);
    benchmark::DoNotOptimize(w);
  }
}
BENCHMARK(BM_ForceSafetyApply);

}  // namespace

BENCHMARK_MAIN();
