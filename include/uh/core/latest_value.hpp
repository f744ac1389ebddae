#pragma once
/// \file
/// LatestValue<T>: a lock-free triple buffer handing the newest value of T from one writer thread
/// to one reader thread (e.g. a ContactFrame from the collision thread to the haptic thread).
///
/// The writer fills write_buffer() and calls publish() (or calls write(value)); it never blocks
/// and never waits for the reader. The reader calls update(), which returns true when a newer
/// complete value arrived since its last update, then reads read_buffer(). The reader never sees
/// a value that is being written (no tearing) and always gets the newest published one;
/// intermediate values the reader did not pick up in time are dropped, by design.
///
/// T must be default constructible. It may be large, or own storage of its own (a ContactFrame's
/// pairs): the three slots live on the heap, allocated once by the constructor and
/// value-initialised, and a value is handed over in place, never copied, by write_buffer() and
/// publish() on one side and update() and read_buffer() on the other; write() and try_read() copy
/// and need a copyable T. Each slot is aligned to a cache line so that small values do not share
/// one between threads. A slot's own storage belongs to whichever side holds the slot: the writer
/// may grow it while filling the write buffer, the reader may use (not grow) the read buffer.
///
/// Threads: exactly one writer thread (write_buffer, publish, write) and exactly one reader thread
/// (update, read_buffer, try_read, has_value) at a time. The roles may change hands only through
/// an outside synchronisation point (e.g. a thread start or join). All these calls are real-time
/// safe: no allocation, no lock, one atomic exchange per publish/update; write() and try_read()
/// additionally copy one T.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <type_traits>

namespace uh {

template <typename T>
class LatestValue {
  static_assert(std::is_default_constructible_v<T>, "uh::LatestValue<T>: T must be default constructible");

 public:
  /// Allocates the three slots (3 * sizeof(T), rounded up to cache lines). Not real-time safe.
  LatestValue() : slots_(new Slot[3]()) {}
  LatestValue(const LatestValue&) = delete;
  LatestValue& operator=(const LatestValue&) = delete;

  /// The slot the writer fills next. Writer thread. Its contents are an older value (not
  /// necessarily the last one published): overwrite every field you rely on.
  T& write_buffer() { return slots_[write_index_].value; }

  /// Makes the write buffer the newest value and gives the writer a free slot. Writer thread.
  void publish() {
    const std::uint8_t previous = middle_.exchange(static_cast<std::uint8_t>(write_index_ | kFresh),
                                                   std::memory_order_acq_rel);
    write_index_ = previous & kIndexMask;
  }

  /// Copies `value` into the write buffer and publishes it. Writer thread.
  void write(const T& value) requires std::is_copy_assignable_v<T> {
    write_buffer() = value;
    publish();
  }

  /// Takes the newest published value if one arrived since the last update(); returns whether
  /// it did. read_buffer() is unchanged when it returns false. Reader thread.
  bool update() {
    if ((middle_.load(std::memory_order_relaxed) & kFresh) == 0) return false;
    const std::uint8_t previous = middle_.exchange(read_index_, std::memory_order_acq_rel);
    read_index_ = previous & kIndexMask;
    received_ = true;
    return true;
  }

  /// The value taken by the last successful update() (a value-initialised T before the first).
  /// Reader thread; valid until the next update().
  const T& read_buffer() const { return slots_[read_index_].value; }
  /// The same slot, writable: the reader owns it until its next update() (e.g. scratch inside T).
  T& read_buffer() { return slots_[read_index_].value; }

  /// If a newer value arrived, copies it into `out` and returns true; otherwise leaves `out`
  /// untouched and returns false. Reader thread.
  bool try_read(T& out) requires std::is_copy_assignable_v<T> {
    if (!update()) return false;
    out = read_buffer();
    return true;
  }

  /// True once update() has taken at least one published value. Reader thread.
  [[nodiscard]] bool has_value() const { return received_; }

  /// Which of the three slots write_buffer() is (0, 1 or 2). Writer thread. With read_slot(), lets
  /// the two sides keep data beside each slot (an array of three), owned as the slot is: the
  /// writer's while it fills the slot, the reader's from the update() that takes it.
  [[nodiscard]] std::size_t write_slot() const { return write_index_; }
  /// Which of the three slots read_buffer() is. Reader thread.
  [[nodiscard]] std::size_t read_slot() const { return read_index_; }

 private:
  // a slot per cache line (or more for large T) so that writer and reader never share a line
  struct alignas(64) Slot {
    T value{};
  };

  static constexpr std::uint8_t kIndexMask = 0x3;
  static constexpr std::uint8_t kFresh = 0x4;  ///< set in middle_ when it holds an unread value

  std::unique_ptr<Slot[]> slots_;
  alignas(64) std::atomic<std::uint8_t> middle_{1};
  alignas(64) std::uint8_t write_index_ = 0;  ///< writer-owned
  alignas(64) std::uint8_t read_index_ = 2;   ///< reader-owned
  bool received_ = false;                     ///< reader-owned
};

}  // namespace uh
