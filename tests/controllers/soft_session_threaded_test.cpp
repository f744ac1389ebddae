// A soft block in a threaded session (issue 26): its simulation runs on its own thread beside the
// haptic and collision threads (this file runs under ThreadSanitizer too, label "threads"), the
// collision thread queries the trees it publishes, and stop() ends it with the others.

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "scene_test_support.hpp"
#include "soft_block_support.hpp"
#include "uh/controllers/haptic_session.hpp"

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

}  // namespace
}  // namespace uh::controllers
