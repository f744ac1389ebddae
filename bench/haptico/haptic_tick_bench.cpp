// Overhead of one haptic tick outside the force computation: device read, the two broadcasts,
// the safety stage, the command and (optionally) the trace push, in a stepped session.

#include <benchmark/benchmark.h>

#include <memory>
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

}  // namespace

BENCHMARK_MAIN();
