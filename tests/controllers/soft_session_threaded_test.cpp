// A soft block in a threaded session (issue 26): its simulation runs on its own thread beside the
// haptic and collision threads (this file runs under ThreadSanitizer too, label "threads"), the
// collision thread queries the trees it publishes, and stop() ends it with the others.

#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <chrono>
#include <thread>

#include "forwarding_device.hpp"
#include "scene_test_support.hpp"
#include "soft_block_support.hpp"
#include "uh/controllers/haptic_session.hpp"
#include "uh/devices/hardware_drivers.hpp"

namespace uh::controllers {
namespace {

TEST(SoftSessionThreads, TheSimulationThreadStepsBesideTheHapticAndCollisionThreads) {
  SessionOptions options;
  options.cache_dir = testing::fresh_cache("soft-threads");
  auto session = HapticSession::create(testing::soft_block(0.004), options);
  ASSERT_TRUE(session.has_value()) << session.error().message;
  const SoftSimulation* sim = (*session)->soft_simulation(0);
  ASSERT_NE(sim, nullptr);
  EXPECT_EQ((*session)->soft_simulation(1), nullptr);
  // the press (the ball reaches its depth after half a second), until the simulation thread has
  // stepped 50 times, a wait for the event rather than a time: under ThreadSanitizer on a loaded
  // machine a second held fewer than ten steps
  const Status started = (*session)->start();
  ASSERT_TRUE(started) << started.error().message;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (sim->stats().ticks < 50u && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  const Status stopped = (*session)->stop();
  ASSERT_TRUE(stopped) << stopped.error().message;
  EXPECT_GE(sim->stats().ticks, 50u) << "the simulation thread stepped";
  // the report gives the rate the thread kept, from its own loop (not the target)
  const auto& soft = (*session)->report().soft;
  ASSERT_EQ(soft.size(), 1u);
  EXPECT_EQ(soft[0].steps, sim->stats().ticks);
  EXPECT_EQ(soft[0].rate_hz, sim->stats().achieved_rate_hz);
  EXPECT_GT(soft[0].rate_hz, 0.0);
  EXPECT_GT(soft[0].step_p99_ms, 0.0);
  EXPECT_EQ(soft[0].tetrahedra, static_cast<std::int64_t>(sim->body().mesh.tets.size()));
  EXPECT_TRUE(sim->failure());
  EXPECT_GT((*session)->report().contact_ticks, 0u);
  // the block went down under the ball (the loads came back from the haptic thread)
  double indentation = 0.0;
  const auto& rest = sim->body().mesh.nodes;
  for (std::size_t n = 0; n < rest.size(); ++n)
    indentation = std::max(indentation, rest[n].z() - sim->fem().positions()[n].z());
  EXPECT_GT(indentation, 1e-4);
}

// A sim-line device that records every force it is commanded, in order (the haptic thread writes,
// the test reads what the count publishes).
class RecordingDevice final : public testing::ForwardingDevice {
 public:
  static constexpr std::size_t kCapacity = 200000;
  struct Log {
    std::array<Vec3, kCapacity> forces;
    std::atomic<std::size_t> count{0};
  };
  RecordingDevice(std::unique_ptr<haptico::HapticDevice> inner, Log* log)
      : ForwardingDevice(std::move(inner)), log_(log) {}
  void command(const haptico::DeviceCommand& cmd) override {
    const std::size_t n = log_->count.load(std::memory_order_relaxed);
    if (n < kCapacity) {
      log_->forces[n] = cmd.force;
      log_->count.store(n + 1, std::memory_order_release);
    }
    inner().command(cmd);
  }

 private:
  Log* log_;
};

// A soft object's simulation thread that fails while the ball presses the block: every device is
// sent zero from its next tick on (the object would otherwise stand frozen under the tool), the
// session says it ended by itself, and stop() names the object and what failed.
TEST(SoftSessionThreads, AFailedSimulationStepZeroesTheForceAndEndsTheSession) {
  auto log = std::make_unique<RecordingDevice::Log>();
  haptico::DeviceRegistry registry = devices::all_drivers();
  ASSERT_TRUE(registry.register_driver(
      "recording-line",
      [log = log.get()](const haptico::DeviceConfig& c) -> Result<std::unique_ptr<haptico::HapticDevice>> {
        auto inner = haptico::DeviceRegistry::with_simulated_devices().create("sim-line", c);
        if (!inner) return inner.error();
        return std::unique_ptr<haptico::HapticDevice>(new RecordingDevice(std::move(*inner), log));
      }));
  Scene scene = testing::soft_block(0.004);
  scene.tools[0].device.driver = "recording-line";
  SessionOptions options;
  options.cache_dir = testing::fresh_cache("soft-fail");
  auto session = HapticSession::create(scene, options, registry);
  ASSERT_TRUE(session.has_value()) << session.error().message;
  HapticSession& s = **session;
  ASSERT_TRUE(s.start());
  // the ball presses the block (it is down after half a second; waits for the event, not a time)
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (norm(s.state().force_world) < 0.5 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_GE(norm(s.state().force_world), 0.5) << "the ball presses the block";
  EXPECT_FALSE(s.ended_by_itself());

  s.soft_simulation(0)->fail_next_step();
  while (!s.ended_by_itself() && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  ASSERT_TRUE(s.ended_by_itself());
  // a tick that began before the failure may still send what it computed: from the one after on,
  // zero (the haptic threads go on until stop(), at 1 kHz: 30 ticks come meanwhile)
  const std::size_t seen = log->count.load(std::memory_order_acquire);
  while (log->count.load(std::memory_order_acquire) < seen + 30 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  const std::size_t until = log->count.load(std::memory_order_acquire);
  ASSERT_GE(until, seen + 30);
  std::size_t nonzero = 0;
  for (std::size_t i = seen + 1; i < until; ++i) nonzero += norm(log->forces[i]) != 0.0 ? 1 : 0;
  EXPECT_EQ(nonzero, 0u) << "of the " << until - seen - 1 << " commands after the one in flight";
  const Status stopped = s.stop();
  ASSERT_FALSE(stopped);
  EXPECT_EQ(stopped.error().message,
            "object 'block': the simulation stopped: the step was made to fail (fail_next_step)");
  EXPECT_EQ(stopped.error().kind, ErrorKind::kThread);
}

}  // namespace
}  // namespace uh::controllers
