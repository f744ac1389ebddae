#include "uh/core/log.hpp"

#include <gtest/gtest.h>

#include <thread>
#include <vector>

#include "uh/core/event_counter.hpp"

TEST(Log, LevelFiltersAndCounts) {
  const uh::log::Level saved = uh::log::level();
  uh::log::set_level(uh::log::Level::warn);
  EXPECT_FALSE(uh::log::enabled(uh::log::Level::info));
  EXPECT_TRUE(uh::log::enabled(uh::log::Level::error));
  const std::uint64_t infos = uh::log::message_count(uh::log::Level::info);
  const std::uint64_t warns = uh::log::message_count(uh::log::Level::warn);
  uh::log::info("dropped {}", 1);
  uh::log::warn("core log test: expected warning {} of {}", 1, 1);
  EXPECT_EQ(uh::log::message_count(uh::log::Level::info), infos);
  EXPECT_EQ(uh::log::message_count(uh::log::Level::warn), warns + 1);
  uh::log::set_level(uh::log::Level::off);
  EXPECT_FALSE(uh::log::enabled(uh::log::Level::error));
  uh::log::error("dropped too");
  uh::log::set_level(saved);
  EXPECT_EQ(uh::log::level(), saved);
}

TEST(EventCounter, CountsFromSeveralThreads) {
  uh::EventCounter counter;
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&counter] {
      for (int i = 0; i < 10000; ++i) counter.increment();
      counter.add(5);
    });
  }
  for (auto& t : threads) t.join();
  EXPECT_EQ(counter.load(), 4u * 10005u);
  EXPECT_EQ(counter.take(), 4u * 10005u);
  EXPECT_EQ(counter.load(), 0u);
  counter.add(3);
  counter.reset();
  EXPECT_EQ(counter.load(), 0u);
}
