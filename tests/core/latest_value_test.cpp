#include "uh/core/latest_value.hpp"

#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <thread>

#include "uh/core/contact.hpp"

namespace {

// every field holds the same sequence number, so a torn read shows up as a mismatch
struct Stamped {
  std::uint64_t sequence = 0;
  std::array<std::uint64_t, 61> copies{};
  std::uint64_t tail = 0;
};

void stamp(Stamped& s, std::uint64_t seq) {
  s.sequence = seq;
  s.copies.fill(seq);
  s.tail = seq;
}

bool consistent(const Stamped& s) {
  for (std::uint64_t c : s.copies) {
    if (c != s.sequence) return false;
  }
  return s.tail == s.sequence;
}

}  // namespace

TEST(LatestValue, StartsEmptyAndValueInitialised) {
  uh::LatestValue<Stamped> v;
  EXPECT_FALSE(v.update());
  EXPECT_FALSE(v.has_value());
  EXPECT_EQ(v.read_buffer().sequence, 0u);
  EXPECT_TRUE(consistent(v.read_buffer()));
  Stamped out;
  stamp(out, 77);
  EXPECT_FALSE(v.try_read(out));
  EXPECT_EQ(out.sequence, 77u) << "try_read must leave out untouched when nothing is new";
}

TEST(LatestValue, ReaderGetsTheNewestValueOnce) {
  uh::LatestValue<Stamped> v;
  for (std::uint64_t seq = 1; seq <= 5; ++seq) {
    stamp(v.write_buffer(), seq);
    v.publish();
  }
  ASSERT_TRUE(v.update());
  EXPECT_EQ(v.read_buffer().sequence, 5u) << "intermediate values are dropped, the newest wins";
  EXPECT_TRUE(consistent(v.read_buffer()));
  EXPECT_TRUE(v.has_value());
  EXPECT_FALSE(v.update()) << "no newer value: update() reports false";
  EXPECT_EQ(v.read_buffer().sequence, 5u) << "read buffer stays valid after a false update()";

  Stamped s;
  stamp(s, 6);
  v.write(s);
  Stamped out;
  ASSERT_TRUE(v.try_read(out));
  EXPECT_EQ(out.sequence, 6u);
  EXPECT_FALSE(v.try_read(out));
}

TEST(LatestValue, AlternatingWritesAndReadsSeeEveryValue) {
  uh::LatestValue<std::uint64_t> v;
  for (std::uint64_t i = 1; i < 100; ++i) {
    v.write(i);
    ASSERT_TRUE(v.update());
    ASSERT_EQ(v.read_buffer(), i);
  }
}

// data kept beside each slot (an array of three indexed by write_slot / read_slot) travels with it
TEST(LatestValue, TheSlotIndicesNameTheSlotsTheBuffersAre) {
  uh::LatestValue<std::uint64_t> v;
  std::array<std::uint64_t, 3> beside{};
  for (std::uint64_t i = 1; i < 20; ++i) {
    ASSERT_LT(v.write_slot(), 3u);
    EXPECT_NE(v.write_slot(), v.read_slot()) << "the writer never fills the slot the reader holds";
    v.write_buffer() = i;
    beside[v.write_slot()] = 10 * i;
    v.publish();
    if (i % 3 == 0) continue;  // now and then the reader misses a value
    ASSERT_TRUE(v.update());
    EXPECT_EQ(v.read_buffer(), i);
    EXPECT_EQ(beside[v.read_slot()], 10 * v.read_buffer());
  }
}

TEST(LatestValue, NoTornOrOlderValuesAcrossThreads) {
  uh::LatestValue<Stamped> v;
  constexpr std::uint64_t kWrites = 200'000;
  std::atomic<bool> done{false};

  std::thread writer([&] {
    for (std::uint64_t seq = 1; seq <= kWrites; ++seq) {
      stamp(v.write_buffer(), seq);
      v.publish();
    }
    done.store(true, std::memory_order_release);
  });

  std::uint64_t last = 0;
  std::uint64_t updates = 0;
  std::uint64_t torn = 0;
  std::uint64_t backwards = 0;
  for (;;) {
    const bool finished = done.load(std::memory_order_acquire);
    if (v.update()) {
      ++updates;
      const Stamped& s = v.read_buffer();
      if (!consistent(s)) ++torn;
      if (s.sequence <= last) ++backwards;
      last = s.sequence;
    }
    if (finished && !v.update()) break;
    if (finished) {
      // one more value may have arrived between the two loads
      const Stamped& s = v.read_buffer();
      if (!consistent(s)) ++torn;
      if (s.sequence <= last) ++backwards;
      last = s.sequence;
      break;
    }
  }
  writer.join();
  EXPECT_EQ(torn, 0u);
  EXPECT_EQ(backwards, 0u);
  EXPECT_EQ(last, kWrites) << "the reader must end with the newest value";
  EXPECT_GT(updates, 0u);
}

TEST(LatestValue, HandsAContactFrameOverInPlaceWithTheStorageItsWriterGrew) {
  auto v = std::make_unique<uh::LatestValue<uh::ContactFrame>>();
  uh::ContactFrame& f = v->write_buffer();
  f.sequence = 9;
  f.resize_pairs(40000);  // more than any fixed capacity the frame ever had
  f.pairs()[39999].leaf_a = 123;
  const uh::SpherePairContact* written = f.pairs().data();
  v->publish();
  ASSERT_TRUE(v->update());
  const uh::ContactFrame& r = v->read_buffer();
  EXPECT_EQ(r.sequence, 9u);
  ASSERT_EQ(r.pair_count, 40000);
  EXPECT_EQ(r.pairs()[39999].leaf_a, 123);
  EXPECT_EQ(r.pairs().data(), written) << "the reader gets the writer's storage, not a copy";
  // the next frame is filled in another slot: small, and the first slot's storage is untouched
  uh::ContactFrame& g = v->write_buffer();
  EXPECT_NE(&g, &r);
  g.resize_pairs(3);
  g.sequence = 10;
  EXPECT_EQ(r.pairs()[39999].leaf_a, 123);
  v->publish();
  ASSERT_TRUE(v->update());
  EXPECT_EQ(v->read_buffer().pair_count, 3);
  EXPECT_LT(v->read_buffer().memory_bytes(), 40000 * sizeof(uh::SpherePairContact));
}
