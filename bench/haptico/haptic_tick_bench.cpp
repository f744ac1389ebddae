// Overhead of one haptic tick outside the force computation: device read, the two broadcasts,
// the safety stage, the command and (optionally) the trace push, in a stepped session.

#include <benchmark/benchmark.h>

#include <chrono>
#include <memory>
#include <thread>
#include <vector>

#include "uh/haptico/haptic_manager.hpp"
#include "uh/haptico/sim_hand_device.hpp"
#include "uh/haptico/sim_line_device.hpp"

namespace {

using namespace uh;
using namespace uh::haptico;

void BM_HapticManagerStep(benchmark::State& state) {
  const bool trace = state.range(0) != 0;
  HapticManager manager(std::make_unique<SimLineDevice>(SimLineOptions{}),
                        {.trace_capacity = trace ? std::size_t{1} << 16 : 0});
  if (!manager.open()) {
    state.SkipWithError("open failed");
    return;
  }
  Vec3 last{};
  manager.move_on_haptic_tick().add_delegate([&](const DeviceState& s) { last = s.position; });
  manager.force_on_haptic_tick().add_delegate(
      [&](const DeviceState& s, DeviceCommand& cmd) { cmd.force += 300.0 * (Vec3{0, 0, -0.01} - s.position); });
  std::vector<TraceSample> drained;
  drained.reserve(std::size_t{1} << 16);
  double t = 0.0;
  for (auto _ : state) {
    t += 0.001;
    const TraceSample s = manager.step(t);
    benchmark::DoNotOptimize(s);
    if (trace && (static_cast<std::uint64_t>(t * 1000.0) & 0x3fff) == 0) {
      // drain now and then, outside the timed region, as a writer thread would
      state.PauseTiming();
      drained.clear();
      manager.drain_trace(drained);
      state.ResumeTiming();
    }
  }
  benchmark::DoNotOptimize(last);
  state.counters["dropped"] = static_cast<double>(manager.stats().trace_dropped);
}
BENCHMARK(BM_HapticManagerStep)->Arg(0)->Arg(1);

void BM_SimHandDeviceTick(benchmark::State& state) {
  SimHandDevice device(SimHandOptions{});
  if (!device.open()) {
    state.SkipWithError("open failed");
    return;
  }
  for (auto _ : state) {
    const DeviceState s = device.read_state();
    device.command({.force = {0, 0, -s.position.z}});
    benchmark::DoNotOptimize(s);
  }
}
BENCHMARK(BM_SimHandDeviceTick);

// A threaded session of one second at the given rate: how well the haptic thread keeps time on
// this machine (with a simulated hand device and a spring delegate), from the loop statistics.
void BM_HapticLoopThreaded(benchmark::State& state) {
  const double rate = static_cast<double>(state.range(0));
  HapticStats stats;
  for (auto _ : state) {
    HapticManager manager(std::make_unique<SimHandDevice>(SimHandOptions{.device = {.rate_hz = rate}}),
                          {.rate_hz = rate});
    manager.force_on_haptic_tick().add_delegate(
        [](const DeviceState& s, DeviceCommand& cmd) { cmd.force += 300.0 * (Vec3{0, 0, -0.01} - s.position); });
    if (!manager.start()) {
      state.SkipWithError("start failed");
      return;
    }
    std::this_thread::sleep_for(std::chrono::seconds(1));
    manager.stop();
    stats = manager.stats();
  }
  state.counters["achieved_hz"] = stats.loop.achieved_rate_hz;
  state.counters["period_err_p50_us"] = stats.loop.period_error.p50_ns * 1e-3;
  state.counters["period_err_p99_us"] = stats.loop.period_error.p99_ns * 1e-3;
  state.counters["period_err_max_us"] = stats.loop.period_error.max_ns * 1e-3;
  state.counters["callback_p99_us"] = stats.loop.callback_duration.p99_ns * 1e-3;
  state.counters["missed"] = static_cast<double>(stats.loop.missed_deadlines);
}
BENCHMARK(BM_HapticLoopThreaded)->Arg(1000)->Arg(4000)->Iterations(1)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
