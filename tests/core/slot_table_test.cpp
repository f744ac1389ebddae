#include "uh/core/slot_table.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

namespace uh::core {
namespace {

TEST(SlotTable, ReleasedIdGoesStaleAndItsSlotComesBackAtTheNextGeneration) {
  SlotTable<int> table(4);
  const SlotId a = *table.occupy();
  table.item(a.index) = 10;
  const SlotId b = *table.occupy();
  EXPECT_NE(a.index, b.index);
  EXPECT_EQ(a.generation, 1u);  // the first generation: a zero id never matches
  EXPECT_FALSE(table.is_live(SlotId{}));
  ASSERT_NE(table.find(a), nullptr);
  EXPECT_EQ(*table.find(a), 10);
  EXPECT_EQ(table.count(), 2);

  table.release(a);
  EXPECT_FALSE(table.is_live(a));
  EXPECT_EQ(table.find(a), nullptr);
  EXPECT_EQ(table.count(), 1);
  table.release(a);  // a stale id: nothing
  EXPECT_EQ(table.count(), 1);

  const SlotId again = *table.occupy();
  EXPECT_EQ(again.index, a.index);
  EXPECT_EQ(again.generation, a.generation + 1);
  EXPECT_FALSE(table.is_live(a));  // the old id does not name the slot's new item
  EXPECT_TRUE(table.is_live(again));
  EXPECT_EQ(table.slots_used(), 2u);
}

TEST(SlotTable, AFullTableGivesNoIdAndNeverLooksPastItsSlots) {
  SlotTable<int> table(3);
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(table.occupy());
  EXPECT_FALSE(table.next_id());
  EXPECT_FALSE(table.occupy());
  EXPECT_FALSE(table.is_live(SlotId{3, 1}));
  EXPECT_FALSE(table.is_live(SlotId{0xffffffffu, 1}));
  table.release(SlotId{1, 1});
  ASSERT_TRUE(table.next_id());
  EXPECT_EQ(table.next_id()->index, 1u);
}

TEST(SlotTable, GenerationsWrapWithinTheirBitsAndSkipBelowTheFirst) {
  SlotTable<int> table(1, /*generation_mask=*/3, /*first_generation=*/1);
  std::vector<std::uint32_t> seen;
  for (int i = 0; i < 5; ++i) {
    const SlotId id = *table.occupy();
    seen.push_back(id.generation);
    table.release(id);
  }
  EXPECT_EQ(seen, (std::vector<std::uint32_t>{1, 2, 3, 1, 2}));
  SlotTable<int> from_zero(1, 1, 0);
  const SlotId z = *from_zero.occupy();
  EXPECT_EQ(z.generation, 0u);
  from_zero.release(z);
  EXPECT_EQ(from_zero.next_id()->generation, 1u);
}

TEST(SlotTable, ForEachLiveVisitsTheOccupiedSlotsInOrder) {
  SlotTable<int> table(300);  // more than one chunk
  std::vector<SlotId> ids;
  for (int i = 0; i < 300; ++i) {
    ids.push_back(*table.occupy());
    table.item(ids.back().index) = i;
  }
  for (int i = 0; i < 300; i += 2) table.release(ids[static_cast<std::size_t>(i)]);
  std::vector<int> visited;
  table.for_each_live([&](SlotId id, int& item) {
    EXPECT_TRUE(table.is_live(id));
    visited.push_back(item);
  });
  ASSERT_EQ(visited.size(), 150u);
  for (std::size_t i = 0; i < visited.size(); ++i) EXPECT_EQ(visited[i], static_cast<int>(2 * i + 1));
}

// A reader checking ids while the writer occupies and releases never sees a released id as live
// (labelled "threads": ThreadSanitizer runs it too).
TEST(SlotTable, ReadersSeeReleasedIdsStaleWhileTheWriterReusesSlots) {
  SlotTable<std::atomic<int>> table(512);
  std::atomic<bool> done{false};
  std::atomic<std::uint32_t> stale_index{0}, stale_generation{0};
  std::atomic<int> stale_seen_live{0};
  std::thread reader([&] {
    while (!done.load(std::memory_order_acquire)) {
      const SlotId stale{stale_index.load(std::memory_order_acquire), stale_generation.load(std::memory_order_acquire)};
      if (stale.generation != 0 && table.is_live(stale)) stale_seen_live.fetch_add(1);
    }
  });
  for (int round = 0; round < 20000; ++round) {
    const SlotId id = *table.occupy();
    table.item(id.index).store(round, std::memory_order_release);
    table.release(id);
    // published only once released: from now on the reader must find it stale
    stale_index.store(id.index, std::memory_order_release);
    stale_generation.store(id.generation, std::memory_order_release);
  }
  done.store(true, std::memory_order_release);
  reader.join();
  EXPECT_EQ(stale_seen_live.load(), 0);
}

}  // namespace
}  // namespace uh::core
