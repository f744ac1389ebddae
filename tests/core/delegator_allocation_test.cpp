#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "allocation_counter.hpp"  // tests/support
#include "uh/core/delegator.hpp"

namespace {

struct Payload {
  std::array<double, 16> values{};
};

double g_sum = 0.0;
void add_first(const Payload& p) { g_sum += p.values[0]; }

struct Accumulator {
  double total = 0.0;
  void on_payload(const Payload& p) { total += p.values[1]; }
};

}  // namespace

TEST(DelegatorAllocation, CounterSeesAllocations) {
  // guards the guard: an armed counter must see a plain allocation
  const uh::test::AllocationCounter counter;
  // operator new called directly: a new-expression could be elided by the optimiser
  void* p = ::operator new(64);
  const std::uint64_t n = counter.count();
  ::operator delete(p);
  EXPECT_EQ(n, 1u);
}

TEST(DelegatorAllocation, BroadcastNeverAllocates) {
  g_sum = 0.0;
  uh::Delegator<const Payload&> d;
  Accumulator acc;
  std::vector<double> seen;
  seen.reserve(8);
  d.add_delegate<&add_first>();
  d.add_delegate<&Accumulator::on_payload>(acc);
  d.add_delegate([&seen](const Payload& p) { seen.push_back(p.values[2]); });
  Payload p;
  p.values[0] = 1.0;
  p.values[1] = 2.0;
  p.values[2] = 3.0;

  const uh::test::AllocationCounter counter;
  for (int i = 0; i < 4; ++i) d.broadcast(p);
  const std::uint64_t allocations = counter.count();
  EXPECT_EQ(allocations, 0u);
  EXPECT_DOUBLE_EQ(g_sum, 4.0);
  EXPECT_DOUBLE_EQ(acc.total, 8.0);
  EXPECT_EQ(seen.size(), 4u);
}

TEST(DelegatorAllocation, BroadcastWithRemovalsDuringItNeverAllocates) {
  uh::Delegator<int> d;
  std::vector<uh::DelegateHandle> handles;
  int calls = 0;
  for (int i = 0; i < 8; ++i) {
    handles.push_back(d.add_delegate([&, i](int) {
      ++calls;
      // each delegate removes itself and the next one
      d.remove_delegate(handles[static_cast<std::size_t>(i)]);
      if (i + 1 < 8) d.remove_delegate(handles[static_cast<std::size_t>(i + 1)]);
    }));
  }
  const uh::test::AllocationCounter counter;
  d.broadcast(0);
  d.broadcast(1);
  const std::uint64_t allocations = counter.count();
  EXPECT_EQ(allocations, 0u);
  EXPECT_EQ(calls, 4);  // delegates 0, 2, 4, 6
  EXPECT_TRUE(d.empty());
}
