#include "uh/core/spsc_queue.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <thread>

#include "allocation_counter.hpp"  // tests/support

TEST(SpscQueue, FifoOrderAndCapacity) {
  uh::SpscQueue<int> q(8);
  EXPECT_EQ(q.capacity(), 8u);
  int out = -1;
  EXPECT_FALSE(q.try_pop(out));
  EXPECT_EQ(q.front(), nullptr);
  for (int i = 0; i < 8; ++i) ASSERT_TRUE(q.try_push(i)) << "capacity " << q.capacity() << " must fit";
  EXPECT_EQ(q.size_approx(), 8u);
  // the underlying queue may hold a few more than asked; it must stop somewhere
  int extra = 0;
  while (q.try_push(100 + extra) && extra < 1000) ++extra;
  EXPECT_LT(extra, 1000) << "a full queue must refuse instead of growing";
  ASSERT_NE(q.front(), nullptr);
  EXPECT_EQ(*q.front(), 0);
  EXPECT_TRUE(q.pop());
  for (int i = 1; i < 8; ++i) {
    ASSERT_TRUE(q.try_pop(out));
    EXPECT_EQ(out, i);
  }
  for (int i = 0; i < extra; ++i) {
    ASSERT_TRUE(q.try_pop(out));
    EXPECT_EQ(out, 100 + i);
  }
  EXPECT_FALSE(q.try_pop(out));
  EXPECT_FALSE(q.pop());
}

TEST(SpscQueue, MoveOnlyElementsAndEmplace) {
  uh::SpscQueue<std::unique_ptr<int>> q(4);
  auto p = std::make_unique<int>(5);
  ASSERT_TRUE(q.try_push(std::move(p)));
  ASSERT_TRUE(q.try_emplace(new int(6)));
  std::unique_ptr<int> out;
  ASSERT_TRUE(q.try_pop(out));
  EXPECT_EQ(*out, 5);
  ASSERT_TRUE(q.try_pop(out));
  EXPECT_EQ(*out, 6);
}

TEST(SpscQueue, PushAndPopNeverAllocateAfterConstruction) {
  uh::SpscQueue<std::uint64_t> q(64);
  std::uint64_t out = 0;
  const uh::test::AllocationCounter counter;
  for (std::uint64_t round = 0; round < 10; ++round) {
    for (std::uint64_t i = 0; i < 64; ++i) (void)q.try_push(i);
    for (int i = 0; i < 100; ++i) (void)q.try_push(round);  // full: refused, no growth
    while (q.try_pop(out)) {
    }
  }
  EXPECT_EQ(counter.count(), 0u);
}

TEST(SpscQueue, KeepsOrderAcrossTwoThreads) {
  uh::SpscQueue<std::uint64_t> q(256);
  constexpr std::uint64_t kCount = 500'000;
  std::thread producer([&] {
    for (std::uint64_t i = 0; i < kCount;) {
      if (q.try_push(i)) {
        ++i;
      } else {
        std::this_thread::yield();
      }
    }
  });
  std::uint64_t expected = 0;
  std::uint64_t out_of_order = 0;
  while (expected < kCount) {
    std::uint64_t v = 0;
    if (q.try_pop(v)) {
      if (v != expected) ++out_of_order;
      expected = v + 1;
    } else {
      std::this_thread::yield();
    }
  }
  producer.join();
  EXPECT_EQ(out_of_order, 0u);
  std::uint64_t leftover = 0;
  EXPECT_FALSE(q.try_pop(leftover));
}
