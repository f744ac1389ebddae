// SideThread: two halves of one thread's work side by side, joined before run_beside returns.
#include "uh/core/side_thread.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

namespace uh {
namespace {

TEST(SideThread, RunsBothHalvesAtOnceAndReturnsWhenBothAreDone) {
  SideThread side;
  for (int round = 0; round < 200; ++round) {
    std::atomic<int> arrived{0};
    std::thread::id here_id, there_id;
    int here_sum = 0, there_sum = 0;
    // each half waits until the other has started: only side by side do both get through
    const auto meet = [&] {
      ++arrived;
      const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(20);
      while (arrived.load() < 2 && std::chrono::steady_clock::now() < give_up) std::this_thread::yield();
    };
    side.run_beside(
        [&] {
          meet();
          here_id = std::this_thread::get_id();
          here_sum = round;
        },
        [&] {
          meet();
          there_id = std::this_thread::get_id();
          there_sum = 2 * round;
        });
    // written by the side thread, read here after the join
    ASSERT_EQ(arrived.load(), 2);
    EXPECT_EQ(here_sum, round);
    EXPECT_EQ(there_sum, 2 * round);
    EXPECT_EQ(here_id, std::this_thread::get_id());
    EXPECT_NE(there_id, here_id);
  }
}

}  // namespace
}  // namespace uh
