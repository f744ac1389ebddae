// Uses the installed headers and libraries: a delegator, a short fixed-rate loop, a latest-value
// handoff, an SPSC queue (whose readerwriterqueue headers the package config finds), the logger. Prints "consumer ok" and exits 0 when everything behaved.

#include <uh/core/delegator.hpp>
#include <uh/core/fixed_rate_loop.hpp>
#include <uh/core/latest_value.hpp>
#include <uh/core/log.hpp>
#include <uh/core/math.hpp>
#include <uh/core/spsc_queue.hpp>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <thread>

namespace {

struct Counter {
  int calls = 0;
  void on_tick(const uh::TickInfo&) { ++calls; }
};

}  // namespace

int main() {
  uh::Delegator<const uh::TickInfo&> on_tick;
  Counter counter;
  on_tick.add_delegate<&Counter::on_tick>(counter);
  std::atomic<int> lambda_calls{0};
  uh::ScopedConnection connection = on_tick.connect([&](const uh::TickInfo&) { lambda_calls.fetch_add(1); });

  uh::LatestValue<uh::Vec3> latest;
  uh::SpscQueue<int> ticks_seen(64);
  uh::FixedRateLoop loop({.rate_hz = 1000.0, .name = "consumer"});
  const uh::Status started = loop.start([&](const uh::TickInfo& tick) {
    on_tick.broadcast(tick);
    latest.write(uh::Vec3{static_cast<double>(tick.index), 0.0, 0.0});
    (void)ticks_seen.try_push(static_cast<int>(tick.index));
    if (tick.index >= 19) loop.request_stop();
  });
  if (!started) {
    std::fprintf(stderr, "consumer: %s\n", started.error().message.c_str());
    return 1;
  }
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (loop.running() && std::chrono::steady_clock::now() < give_up) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  loop.stop();

  const uh::FixedRateLoopStats stats = loop.stats();
  uh::Vec3 last{};
  const bool got = latest.try_read(last);
  int queued = 0;
  for (int index = 0; ticks_seen.try_pop(index);) ++queued;
  uh::log::info("consumer: {} ticks, last index {}, {} queued", stats.ticks, last.x, queued);
  if (stats.ticks != 20 || queued != 20 || counter.calls != 20 || lambda_calls.load() != 20 || !got || last.x != 19.0) {
    std::fprintf(stderr, "consumer: unexpected results (ticks %llu, calls %d/%d)\n",
                 static_cast<unsigned long long>(stats.ticks), counter.calls, lambda_calls.load());
    return 1;
  }
  std::printf("consumer ok\n");
  return 0;
}
