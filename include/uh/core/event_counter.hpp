#pragma once
/// \file
/// EventCounter: a lock-free event count for real-time paths (after Jolt's and MuJoCo's warning
/// counters). Real-time code increments it instead of logging; a non-real-time thread reads it
/// and reports (e.g. with uh::log::warn).
///
/// Threads: any number of threads may add() and read concurrently; all operations are relaxed
/// atomics, real-time safe, and never allocate. The count orders nothing else: it is a counter,
/// not a synchronisation flag.

#include <atomic>
#include <cstdint>

namespace uh {

class EventCounter {
 public:
  EventCounter() = default;
  EventCounter(const EventCounter&) = delete;
  EventCounter& operator=(const EventCounter&) = delete;

  /// Counts one event. Real-time safe.
  void increment() { count_.fetch_add(1, std::memory_order_relaxed); }
  /// Counts `n` events. Real-time safe.
  void add(std::uint64_t n) { count_.fetch_add(n, std::memory_order_relaxed); }
  /// Events counted so far. Any thread.
  [[nodiscard]] std::uint64_t load() const { return count_.load(std::memory_order_relaxed); }
  /// Returns the count and sets it to zero in one step (for periodic reports). Any thread.
  std::uint64_t take() { return count_.exchange(0, std::memory_order_relaxed); }
  /// Sets the count to zero. Any thread.
  void reset() { count_.store(0, std::memory_order_relaxed); }

 private:
  std::atomic<std::uint64_t> count_{0};
};

}  // namespace uh
