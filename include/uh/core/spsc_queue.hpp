#pragma once
/// \file
/// SpscQueue<T>: a bounded lock-free queue from one producer thread to one consumer thread, for
/// events that must all arrive in order (button presses, commands, log records from a real-time
/// thread). Wraps moodycamel::ReaderWriterQueue (Debian package libreaderwriterqueue-dev) and
/// only ever uses its non-allocating operations.
///
/// Capacity is fixed at construction: try_push() fails (returns false) instead of growing when
/// the queue is full; the caller counts the drop (see EventCounter). The underlying queue may
/// round the capacity up, so at least `capacity` elements fit; capacity() reports the guaranteed
/// figure.
///
/// Threads: exactly one producer thread (try_push, try_emplace) and one consumer thread
/// (try_pop, front, pop) at a time; size_approx() from either. After construction every call is
/// real-time safe (no allocation, no lock) provided T's copy/move constructors are.

#include <cassert>
#include <cstddef>
#include <utility>

// The queue synchronises with atomic fences, which ThreadSanitizer does not model. Under clang
// the queue tells TSan about them through happens-before annotations; g++ 12 lacks the
// __has_feature test it uses for that, so switch the same annotations on for g++ here.
#if defined(__SANITIZE_THREAD__) && !defined(AE_TSAN_ANNOTATE_RELEASE)
namespace moodycamel {
inline int ae_tsan_global;
}
extern "C" void AnnotateHappensBefore(const char*, int, void*);
extern "C" void AnnotateHappensAfter(const char*, int, void*);
#define AE_TSAN_ANNOTATE_RELEASE() AnnotateHappensBefore(__FILE__, __LINE__, static_cast<void*>(&::moodycamel::ae_tsan_global))
#define AE_TSAN_ANNOTATE_ACQUIRE() AnnotateHappensAfter(__FILE__, __LINE__, static_cast<void*>(&::moodycamel::ae_tsan_global))
#endif

#include <readerwriterqueue/readerwriterqueue.h>

namespace uh {

template <typename T>
class SpscQueue {
 public:
  /// Allocates room for at least `capacity` elements (> 0). Not real-time safe.
  explicit SpscQueue(std::size_t capacity) : capacity_(capacity), queue_(capacity) {
    assert(capacity > 0 && "uh::SpscQueue::SpscQueue(): capacity must be > 0");
  }
  SpscQueue(const SpscQueue&) = delete;
  SpscQueue& operator=(const SpscQueue&) = delete;

  /// Appends a copy of `value`; false (and nothing stored) if the queue is full. Producer thread.
  bool try_push(const T& value) { return queue_.try_enqueue(value); }
  /// Appends `value` by move; false (and `value` untouched) if the queue is full. Producer thread.
  bool try_push(T&& value) { return queue_.try_enqueue(std::move(value)); }
  /// Constructs an element in place; false if the queue is full. Producer thread.
  template <typename... Ts>
  bool try_emplace(Ts&&... args) {
    return queue_.try_emplace(std::forward<Ts>(args)...);
  }

  /// Moves the oldest element into `out`; false if the queue is empty. Consumer thread.
  bool try_pop(T& out) { return queue_.try_dequeue(out); }
  /// The oldest element, or nullptr if empty; valid until pop(). Consumer thread.
  T* front() { return queue_.peek(); }
  /// Removes the oldest element; false if empty. Consumer thread.
  bool pop() { return queue_.pop(); }

  /// Number of elements, exact only when neither thread is working. Either thread.
  [[nodiscard]] std::size_t size_approx() const { return queue_.size_approx(); }
  /// Elements that always fit (the capacity asked for).
  [[nodiscard]] std::size_t capacity() const { return capacity_; }

 private:
  std::size_t capacity_;
  moodycamel::ReaderWriterQueue<T> queue_;
};

}  // namespace uh
