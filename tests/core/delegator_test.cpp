#include "uh/core/delegator.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace {

std::vector<std::string>* g_trace = nullptr;

void free_a(int v) { g_trace->push_back("free_a:" + std::to_string(v)); }
void free_b(int v) { g_trace->push_back("free_b:" + std::to_string(v)); }

struct Listener {
  std::vector<std::string>* trace = nullptr;
  int total = 0;
  void on_value(int v) {
    total += v;
    trace->push_back("member:" + std::to_string(v));
  }
  void on_value_const(int v) const { trace->push_back("const_member:" + std::to_string(v)); }
};

void with_payload(Listener& l, int v) { l.trace->push_back("payload:" + std::to_string(v + l.total)); }

// counts copies and moves so the tests can prove arguments travel by reference
struct Counted {
  static inline int copies = 0;
  static inline int moves = 0;
  int value = 0;
  explicit Counted(int v) : value(v) {}
  Counted(const Counted& o) : value(o.value) { ++copies; }
  Counted(Counted&& o) noexcept : value(o.value) { ++moves; }
  Counted& operator=(const Counted& o) {
    value = o.value;
    ++copies;
    return *this;
  }
  Counted& operator=(Counted&& o) noexcept {
    value = o.value;
    ++moves;
    return *this;
  }
  ~Counted() = default;
};

int g_counted_sum = 0;
void take_counted(const Counted& c) { g_counted_sum += c.value; }

class DelegatorTest : public ::testing::Test {
 protected:
  void SetUp() override { g_trace = &trace; }
  void TearDown() override { g_trace = nullptr; }
  std::vector<std::string> trace;
};

}  // namespace

TEST_F(DelegatorTest, CallsAllBindingKindsInBindOrder) {
  uh::Delegator<int> d;
  Listener listener{&trace};
  const Listener const_listener{&trace};
  EXPECT_TRUE(d.empty());
  d.add_delegate<&free_a>();
  d.add_delegate<&Listener::on_value>(listener);
  d.add_delegate<&Listener::on_value_const>(const_listener);
  d.add_delegate<&with_payload>(listener);
  int captured = 100;
  d.add_delegate([this, captured](int v) { trace.push_back("lambda:" + std::to_string(v + captured)); });
  d.add_delegate<&free_b>();
  EXPECT_EQ(d.size(), 6u);
  EXPECT_FALSE(d.empty());

  d.broadcast(7);
  const std::vector<std::string> expected{"free_a:7", "member:7", "const_member:7", "payload:14", "lambda:107",
                                          "free_b:7"};
  EXPECT_EQ(trace, expected);
  EXPECT_EQ(listener.total, 7);
}

TEST_F(DelegatorTest, PassesArgumentsByReferenceWithoutCopies) {
  Counted::copies = 0;
  Counted::moves = 0;
  g_counted_sum = 0;
  {
    uh::Delegator<Counted> by_value_signature;  // delegates still receive const Counted&
    by_value_signature.add_delegate<&take_counted>();
    by_value_signature.add_delegate([](const Counted& c) { g_counted_sum += 10 * c.value; });
    const Counted c(3);
    by_value_signature.broadcast(c);
    by_value_signature.broadcast(Counted(1));  // a temporary binds to the reference too
  }
  {
    uh::Delegator<const Counted&> by_ref;
    const Counted* seen = nullptr;
    by_ref.add_delegate([&seen](const Counted& c) { seen = &c; });
    const Counted c(5);
    by_ref.broadcast(c);
    EXPECT_EQ(seen, &c);
  }
  EXPECT_EQ(g_counted_sum, 33 + 11);
  EXPECT_EQ(Counted::copies, 0);
  EXPECT_EQ(Counted::moves, 0);
}

TEST_F(DelegatorTest, MutableReferenceArgumentIsSharedInOrder) {
  uh::Delegator<double&> d;
  d.add_delegate([](double& f) { f += 1.0; });
  d.add_delegate([](double& f) { f *= 3.0; });
  double force = 1.0;
  d.broadcast(force);
  EXPECT_DOUBLE_EQ(force, 6.0);
}

TEST_F(DelegatorTest, SeveralArguments) {
  uh::Delegator<int, const std::string&, double&> d;
  d.add_delegate([](int a, const std::string& s, double& out) { out = a + static_cast<double>(s.size()); });
  double out = 0.0;
  d.broadcast(2, std::string("abc"), out);
  EXPECT_DOUBLE_EQ(out, 5.0);
}

TEST_F(DelegatorTest, RemoveByHandle) {
  uh::Delegator<int> d;
  const uh::DelegateHandle a = d.add_delegate<&free_a>();
  const uh::DelegateHandle b = d.add_delegate<&free_b>();
  EXPECT_NE(a, b);
  EXPECT_TRUE(d.remove_delegate(a));
  EXPECT_FALSE(d.remove_delegate(a)) << "second removal must report false";
  EXPECT_FALSE(d.remove_delegate(uh::DelegateHandle{}));
  EXPECT_EQ(d.size(), 1u);
  d.broadcast(1);
  EXPECT_EQ(trace, (std::vector<std::string>{"free_b:1"}));
}

TEST_F(DelegatorTest, HandleOfAnotherDelegatorIsUnknown) {
  uh::Delegator<int> d1;
  uh::Delegator<int> d2;
  const uh::DelegateHandle h1 = d1.add_delegate<&free_a>();
  d2.add_delegate<&free_b>();
  EXPECT_FALSE(d2.remove_delegate(h1));
  EXPECT_EQ(d2.size(), 1u);
  EXPECT_EQ(d1.size(), 1u);
}

TEST_F(DelegatorTest, ClearRemovesEverything) {
  uh::Delegator<int> d;
  d.add_delegate<&free_a>();
  d.add_delegate([](int) { FAIL() << "cleared delegate called"; });
  d.clear();
  EXPECT_TRUE(d.empty());
  d.broadcast(1);
  EXPECT_TRUE(trace.empty());
}

TEST_F(DelegatorTest, ScopedConnectionRemovesOnDestruction) {
  uh::Delegator<int> d;
  int calls = 0;
  {
    uh::ScopedConnection c = d.connect([&calls](int) { ++calls; });
    EXPECT_TRUE(c.connected());
    d.broadcast(0);
    EXPECT_EQ(d.size(), 1u);
  }
  EXPECT_EQ(d.size(), 0u);
  d.broadcast(0);
  EXPECT_EQ(calls, 1);
}

TEST_F(DelegatorTest, ScopedConnectionMovesAndReleases) {
  uh::Delegator<int> d;
  Listener listener{&trace};
  uh::ScopedConnection outer;
  EXPECT_FALSE(outer.connected());
  {
    uh::ScopedConnection inner = d.connect<&Listener::on_value>(listener);
    outer = std::move(inner);
    EXPECT_FALSE(inner.connected());  // NOLINT(bugprone-use-after-move): moved-from state is specified
  }
  EXPECT_EQ(d.size(), 1u) << "the moved-from connection must not remove the binding";
  outer.disconnect();
  EXPECT_EQ(d.size(), 0u);
  outer.disconnect();  // idempotent

  uh::DelegateHandle kept;
  {
    uh::ScopedConnection c = d.connect<&free_a>();
    kept = c.release();
  }
  EXPECT_EQ(d.size(), 1u) << "a released connection leaves the binding in place";
  EXPECT_TRUE(d.remove_delegate(kept));

  // move-assigning onto a live connection drops the old binding
  uh::ScopedConnection a = d.connect<&free_a>();
  uh::ScopedConnection b = d.connect<&free_b>();
  a = std::move(b);
  EXPECT_EQ(d.size(), 1u);
  d.broadcast(4);
  EXPECT_EQ(trace, (std::vector<std::string>{"free_b:4"}));
}

TEST_F(DelegatorTest, ScopedConnectionAfterManualRemovalIsHarmless) {
  uh::Delegator<int> d;
  uh::ScopedConnection c = d.connect<&free_a>();
  EXPECT_TRUE(d.remove_delegate(c.handle()));
  c.disconnect();
  EXPECT_TRUE(d.empty());
}

TEST_F(DelegatorTest, SelfRemovalDuringBroadcast) {
  uh::Delegator<int> d;
  uh::DelegateHandle self;
  int self_calls = 0;
  auto big = std::make_shared<int>(42);  // a capture whose destruction we can observe
  std::weak_ptr<int> watch = big;
  self = d.add_delegate([&, big](int) {
    ++self_calls;
    EXPECT_TRUE(d.remove_delegate(self));
    // the closure must still be alive after removing itself
    EXPECT_EQ(*big, 42);
  });
  big.reset();
  d.add_delegate<&free_a>();
  d.broadcast(1);
  d.broadcast(2);
  EXPECT_EQ(self_calls, 1);
  EXPECT_EQ(trace, (std::vector<std::string>{"free_a:1", "free_a:2"}));
  EXPECT_FALSE(watch.expired()) << "removed during broadcast: destroyed only at the next mutation";
  d.add_delegate<&free_b>();  // a mutation outside broadcast compacts
  EXPECT_TRUE(watch.expired());
  EXPECT_EQ(d.size(), 2u);
}

TEST_F(DelegatorTest, RemovingALaterDelegateDuringBroadcastSkipsIt) {
  uh::Delegator<int> d;
  uh::DelegateHandle later;
  int first_calls = 0;
  d.add_delegate([&](int) {
    ++first_calls;
    d.remove_delegate(later);
  });
  later = d.add_delegate([](int) { FAIL() << "removed before being reached"; });
  d.add_delegate<&free_a>();
  d.broadcast(5);
  EXPECT_EQ(first_calls, 1);
  EXPECT_EQ(d.size(), 2u);
  EXPECT_EQ(trace, (std::vector<std::string>{"free_a:5"}));
}

TEST_F(DelegatorTest, RemovingAnEarlierDelegateDuringBroadcast) {
  uh::Delegator<int> d;
  const uh::DelegateHandle first = d.add_delegate<&free_a>();
  std::vector<bool> removed;
  d.add_delegate([&](int) { removed.push_back(d.remove_delegate(first)); });
  d.add_delegate<&free_b>();
  d.broadcast(1);
  d.broadcast(2);
  EXPECT_EQ(trace, (std::vector<std::string>{"free_a:1", "free_b:1", "free_b:2"}));
  EXPECT_EQ(removed, (std::vector<bool>{true, false}));
}

TEST_F(DelegatorTest, AddingDuringBroadcastTakesEffectNextTime) {
  uh::Delegator<int> d;
  int added_calls = 0;
  bool added = false;
  d.add_delegate([&](int) {
    if (!added) {
      added = true;
      // many bindings force a reallocation of the slot array during the broadcast
      for (int i = 0; i < 64; ++i) d.add_delegate([&added_calls](int) { ++added_calls; });
    }
  });
  d.add_delegate<&free_a>();
  d.broadcast(1);
  EXPECT_EQ(added_calls, 0);
  EXPECT_EQ(trace, (std::vector<std::string>{"free_a:1"}));
  d.broadcast(2);
  EXPECT_EQ(added_calls, 64);
  EXPECT_EQ(d.size(), 66u);
}

TEST_F(DelegatorTest, ClearDuringBroadcastStopsTheRest) {
  uh::Delegator<int> d;
  d.add_delegate<&free_a>();
  d.add_delegate([&](int) { d.clear(); });
  d.add_delegate([](int) { FAIL() << "called after clear()"; });
  d.broadcast(3);
  EXPECT_TRUE(d.empty());
  EXPECT_EQ(trace, (std::vector<std::string>{"free_a:3"}));
  d.add_delegate<&free_b>();
  d.broadcast(4);
  EXPECT_EQ(trace, (std::vector<std::string>{"free_a:3", "free_b:4"}));
}

TEST_F(DelegatorTest, NestedBroadcast) {
  uh::Delegator<int> d;
  d.add_delegate([&](int depth) {
    trace.push_back("outer:" + std::to_string(depth));
    if (depth < 2) d.broadcast(depth + 1);
  });
  d.broadcast(0);
  EXPECT_EQ(trace, (std::vector<std::string>{"outer:0", "outer:1", "outer:2"}));
}

TEST_F(DelegatorTest, ExceptionFromDelegateLeavesDelegatorUsable) {
  uh::Delegator<int> d;
  uh::DelegateHandle thrower = d.add_delegate([](int v) {
    if (v == 1) throw std::runtime_error("boom");
  });
  d.add_delegate<&free_a>();
  EXPECT_THROW(d.broadcast(1), std::runtime_error);
  EXPECT_TRUE(d.remove_delegate(thrower));
  EXPECT_EQ(d.size(), 1u) << "removal after the throw must compact, as outside any broadcast";
  d.broadcast(2);
  EXPECT_EQ(trace, (std::vector<std::string>{"free_a:2"}));
}

namespace {

// a class that keeps its delegator private and hands out a sink
class Emitter {
 public:
  uh::DelegateSink<int> on_value() { return uh::DelegateSink{value_event_}; }
  void emit(int v) { value_event_.broadcast(v); }

 private:
  uh::Delegator<int> value_event_;
};

}  // namespace

TEST_F(DelegatorTest, SinkBindsAndRemovesOnly) {
  Emitter emitter;
  Listener listener{&trace};
  auto sink = emitter.on_value();
  const uh::DelegateHandle h = sink.add_delegate<&free_a>();
  sink.add_delegate<&Listener::on_value>(listener);
  {
    uh::ScopedConnection c = emitter.on_value().connect([this](int v) { trace.push_back("scoped:" + std::to_string(v)); });
    emitter.emit(1);
  }
  EXPECT_TRUE(sink.remove_delegate(h));
  EXPECT_EQ(sink.size(), 1u);
  emitter.emit(2);
  EXPECT_EQ(trace, (std::vector<std::string>{"free_a:1", "member:1", "scoped:1", "member:2"}));
}

TEST_F(DelegatorTest, NoArgumentEvents) {
  uh::Delegator<> d;
  int calls = 0;
  d.add_delegate([&calls] { ++calls; });
  d.broadcast();
  d.broadcast();
  EXPECT_EQ(calls, 2);
}

// compile-time contracts: a sink cannot broadcast; connections move but do not copy; a delegator
// neither copies nor moves (sinks and connections point at it)
template <typename T>
concept CanBroadcastInt = requires(T t) { t.broadcast(1); };
static_assert(!CanBroadcastInt<uh::DelegateSink<int>>);
static_assert(CanBroadcastInt<uh::Delegator<int>>);
static_assert(std::is_nothrow_move_constructible_v<uh::ScopedConnection>);
static_assert(!std::is_copy_constructible_v<uh::ScopedConnection>);
static_assert(!std::is_copy_constructible_v<uh::Delegator<int>>);
static_assert(!std::is_move_constructible_v<uh::Delegator<int>>);
// arguments reach delegates by reference: the thunk signature shows it
static_assert(std::is_same_v<uh::Delegator<std::string>::Thunk, void (*)(void*, const std::string&)>);
static_assert(std::is_same_v<uh::Delegator<double&>::Thunk, void (*)(void*, double&)>);

TEST_F(DelegatorTest, RefusedBindingIsVisibleAndBindsNothing) {
  uh::Delegator<int> d;
  Listener listener{&trace};
  d.add_delegate<&free_a>();
  d.refuse_binding("test: the broadcasting thread runs");
  EXPECT_TRUE(d.binding_refused());
  const std::uint64_t errors_before = uh::log::message_count(uh::log::Level::error);
  // every binding kind is refused: invalid handles, empty connections, nothing called
  EXPECT_FALSE(d.add_delegate<&free_b>().valid());
  EXPECT_FALSE(d.add_delegate<&Listener::on_value>(listener).valid());
  auto owned = std::make_shared<int>(7);
  EXPECT_FALSE(d.add_delegate([owned](int) { g_trace->push_back("lambda"); }).valid());
  EXPECT_EQ(owned.use_count(), 1) << "the refused lambda's copy is destroyed at once";
  uh::ScopedConnection c = d.connect([](int) { g_trace->push_back("connected"); });
  EXPECT_FALSE(c.connected());
  EXPECT_EQ(d.size(), 1u);
  EXPECT_EQ(d.refused_bindings(), 4u);
  EXPECT_EQ(uh::log::message_count(uh::log::Level::error) - errors_before, 4u) << "each refusal is logged";
  d.broadcast(1);
  EXPECT_EQ(trace, (std::vector<std::string>{"free_a:1"}));
  // allowed again: binding works as before
  d.allow_binding();
  EXPECT_TRUE(d.add_delegate<&free_b>().valid());
  d.broadcast(2);
  EXPECT_EQ(trace, (std::vector<std::string>{"free_a:1", "free_a:2", "free_b:2"}));
}
