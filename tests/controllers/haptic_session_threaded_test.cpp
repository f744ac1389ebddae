#include "uh/controllers/haptic_session.hpp"

#include <gtest/gtest.h>

#include "scene_test_support.hpp"

namespace uh::controllers {
namespace {

// Runs the real three-thread pipeline (haptic, collision, application) for 2 s. Under
// ThreadSanitizer this checks every cross-thread exchange of the pipeline.
TEST(HapticSessionThreaded, TwoSecondSessionRunsAllThreadsAndEndsWithZeroForce) {
  const auto cache = testing::fresh_cache("threaded");
  auto scene = parse_scene(testing::small_scene_json(), "small.json", testing::test_assets());
  ASSERT_TRUE(scene.has_value()) << scene.error().message;
  SessionOptions options;
  options.cache_dir = cache;
  auto session = HapticSession::create(*scene, options);
  ASSERT_TRUE(session.has_value()) << session.error().message;
  int status_calls = 0;
  ASSERT_TRUE((*session)->run(2.0, [&](const LiveStatus&) { ++status_calls; }).has_value());
  const SessionReport& r = (*session)->report();
  EXPECT_GT(r.haptic_ticks, 500u) << "about 2000 ticks at 1 kHz; loose bound for sanitizer builds";
  EXPECT_GT(r.collision_steps, 50u);
  EXPECT_GT(r.contact_ticks, 0u) << "the stylus reaches the bunny within 2 s";
  EXPECT_LE(r.force_max_n, 6.0 + 1e-9);
  EXPECT_EQ(r.force_nonfinite, 0u);
  EXPECT_GT(status_calls, 2);
  ASSERT_FALSE(r.timeline.empty());
  EXPECT_FALSE((*session)->world().running());
  std::filesystem::remove_all(cache);
}

}  // namespace
}  // namespace uh::controllers
