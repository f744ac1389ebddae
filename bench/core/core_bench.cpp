// Core runtime benchmarks: delegator broadcast against a std::function loop (same run), the
// fixed-rate loop's timing at 1 kHz and 4 kHz (idle and with the other core busy), and the
// cross-thread handoff primitives.
//
// The loop benchmarks run for --uh_loop_seconds seconds each (default 10; the flag is taken out
// of argv before Google Benchmark parses it), e.g.
//   uh_core_bench --benchmark_filter=FixedRateLoop --uh_loop_seconds=2

#include <benchmark/benchmark.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "uh/core/delegator.hpp"
#include "uh/core/fixed_rate_loop.hpp"
#include "uh/core/latest_value.hpp"
#include "uh/core/spsc_queue.hpp"

namespace {

double g_loop_seconds = 10.0;

struct Force {
  double x = 1.0, y = 2.0, z = 3.0;
};

// the work every delegate does: small, but not removable by the optimiser
struct Accumulator {
  double total = 0.0;
  void on_force(const Force& f) { total += f.x; }
};

// one broadcast to n delegates bound as member functions (kLambda false) or as capturing lambdas
template <bool kLambda>
void delegator_broadcast(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  std::vector<Accumulator> targets(n);
  uh::Delegator<const Force&> d;
  for (auto& t : targets) {
    if constexpr (kLambda) {
      d.add_delegate([p = &t](const Force& f) { p->on_force(f); });
    } else {
      d.add_delegate<&Accumulator::on_force>(t);
    }
  }
  Force f;
  for (auto _ : state) {
    benchmark::DoNotOptimize(&f);
    d.broadcast(f);
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * state.range(0));
  state.counters["ns_per_delegate"] = benchmark::Counter(
      static_cast<double>(state.iterations()) * static_cast<double>(n),
      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
void BM_DelegatorBroadcast(benchmark::State& state) { delegator_broadcast<false>(state); }
void BM_DelegatorBroadcastLambda(benchmark::State& state) { delegator_broadcast<true>(state); }
BENCHMARK(BM_DelegatorBroadcast)->Arg(1)->Arg(4)->Arg(16)->Arg(64);
BENCHMARK(BM_DelegatorBroadcastLambda)->Arg(1)->Arg(4)->Arg(16)->Arg(64);

// the baseline a user would write instead: a vector of std::function called in a loop
void BM_StdFunctionLoop(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  std::vector<Accumulator> targets(n);
  std::vector<std::function<void(const Force&)>> fs;
  for (auto& t : targets) fs.emplace_back([p = &t](const Force& f) { p->on_force(f); });
  Force f;
  for (auto _ : state) {
    benchmark::DoNotOptimize(&f);
    for (const auto& fn : fs) fn(f);
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * state.range(0));
  state.counters["ns_per_delegate"] = benchmark::Counter(
      static_cast<double>(state.iterations()) * static_cast<double>(n),
      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_StdFunctionLoop)->Arg(1)->Arg(4)->Arg(16)->Arg(64);

// Runs a FixedRateLoop with an empty callback for g_loop_seconds. range(0) = rate [Hz],
// range(1) = 1 to keep the other core busy with a spinning thread started here (a second
// std::thread incrementing a counter until the loop stops), range(2) = 1 to ask for SCHED_FIFO,
// range(3) = spin_us, the busy-wait before each deadline [us].
void BM_FixedRateLoop(benchmark::State& state) {
  const double rate = static_cast<double>(state.range(0));
  const bool busy = state.range(1) != 0;
  const bool fifo = state.range(2) != 0;
  const auto spin_us = static_cast<double>(state.range(3));
  for (auto _ : state) {
    std::atomic<bool> stop_busy{false};
    std::thread hog;
    if (busy) {
      hog = std::thread([&stop_busy] {
        std::uint64_t x = 0;
        while (!stop_busy.load(std::memory_order_relaxed)) benchmark::DoNotOptimize(++x);
      });
    }
    uh::FixedRateLoop loop({.rate_hz = rate, .raise_priority = fifo, .spin_us = spin_us, .name = "bench-loop"});
    if (!loop.start([](const uh::TickInfo& t) { benchmark::DoNotOptimize(t.index); })) {
      state.SkipWithError("FixedRateLoop::start failed");
      break;
    }
    std::this_thread::sleep_for(std::chrono::duration<double>(g_loop_seconds));
    loop.stop();
    stop_busy.store(true);
    if (hog.joinable()) hog.join();

    const uh::FixedRateLoopStats s = loop.stats();
    state.counters["ticks"] = static_cast<double>(s.ticks);
    state.counters["achieved_hz"] = s.achieved_rate_hz;
    state.counters["err_p50_us"] = s.period_error.p50_ns * 1e-3;
    state.counters["err_p99_us"] = s.period_error.p99_ns * 1e-3;
    state.counters["err_p999_us"] = s.period_error.p999_ns * 1e-3;
    state.counters["err_max_us"] = s.period_error.max_ns * 1e-3;
    state.counters["late_p99_us"] = s.lateness.p99_ns * 1e-3;
    state.counters["missed"] = static_cast<double>(s.missed_deadlines);
    state.counters["skipped"] = static_cast<double>(s.skipped_ticks);
    state.counters["fifo"] = s.priority_raised ? 1.0 : 0.0;
  }
}
BENCHMARK(BM_FixedRateLoop)
    ->ArgNames({"hz", "busy", "fifo", "spin_us"})
    ->Args({1000, 0, 0, 80})
    ->Args({4000, 0, 0, 80})
    ->Args({1000, 1, 0, 80})
    ->Args({4000, 1, 0, 80})
    ->Args({1000, 1, 1, 80})
    ->Args({4000, 1, 1, 80})
    ->Args({8000, 1, 1, 80})
    ->Args({1000, 1, 1, 300})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

struct Pose64 {
  double values[8];
};

void BM_LatestValueWriteUpdate(benchmark::State& state) {
  uh::LatestValue<Pose64> v;
  Pose64 p{};
  for (auto _ : state) {
    p.values[0] += 1.0;
    v.write(p);
    benchmark::DoNotOptimize(v.update());
    benchmark::DoNotOptimize(v.read_buffer().values[0]);
  }
}
BENCHMARK(BM_LatestValueWriteUpdate);

void BM_SpscQueuePushPop(benchmark::State& state) {
  uh::SpscQueue<std::uint64_t> q(1024);
  std::uint64_t i = 0;
  std::uint64_t out = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(q.try_push(i++));
    benchmark::DoNotOptimize(q.try_pop(out));
  }
}
BENCHMARK(BM_SpscQueuePushPop);

}  // namespace

int main(int argc, char** argv) {
  // take --uh_loop_seconds=S out before Google Benchmark sees (and rejects) it
  int kept = 0;
  for (int i = 0; i < argc; ++i) {
    constexpr const char* kFlag = "--uh_loop_seconds=";
    if (std::strncmp(argv[i], kFlag, std::strlen(kFlag)) == 0) {
      g_loop_seconds = std::atof(argv[i] + std::strlen(kFlag));
    } else {
      argv[kept++] = argv[i];
    }
  }
  argc = kept;
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
