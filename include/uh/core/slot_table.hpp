#pragma once
/// \file
/// SlotTable<T>: items behind ids of a slot index and the slot's generation (after Box2D v3's
/// ids). Releasing a slot moves its generation on, so an id kept after its item was released
/// no longer matches, even once the slot holds another item. The project's one such table: the
/// collision world's object and watcher ids, the C API's handles and the audio scene's voices
/// each pack a SlotId into their own id type.
///
/// Threads: one writer (occupy, release, item) and any number of readers of is_live(),
/// generation() and whatever part of an item is itself atomic. Slots live in chunks that never
/// move, allocated by occupy() when the table first grows into them, so a reader never sees a
/// slot move or vanish.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

namespace uh::core {

struct SlotId {
  std::uint32_t index = 0;
  std::uint32_t generation = 0;
};

template <typename T>
class SlotTable {
 public:
  /// At most `capacity` slots; generations count modulo `generation_mask + 1` (the bits an id
  /// type has room for) and start at `first_generation` (1 keeps a zero id from ever matching).
  explicit SlotTable(std::uint32_t capacity, std::uint32_t generation_mask = 0xffffffffu,
                     std::uint32_t first_generation = 1)
      : capacity_(capacity),
        generation_mask_(generation_mask),
        first_generation_(first_generation & generation_mask),
        chunks_(new std::atomic<Chunk*>[chunk_count(capacity)]) {
    for (std::size_t i = 0; i < chunk_count(capacity); ++i) chunks_[i].store(nullptr, std::memory_order_relaxed);
  }
  ~SlotTable() {
    for (std::size_t i = 0; i < chunk_count(capacity_); ++i) delete chunks_[i].load(std::memory_order_relaxed);
  }
  SlotTable(const SlotTable&) = delete;
  SlotTable& operator=(const SlotTable&) = delete;

  /// The id occupy() gives next; none when every slot is in use. Writer.
  std::optional<SlotId> next_id() const {
    if (!free_.empty()) return SlotId{free_.back(), generation(free_.back())};
    if (used_ < capacity_) return SlotId{used_, first_generation_};
    return std::nullopt;
  }

  /// Takes the slot of next_id() (reusing the slot released last, else a new one) and returns its
  /// id; none when the table is full. The slot's item keeps what it held before. Writer.
  std::optional<SlotId> occupy() {
    const std::optional<SlotId> id = next_id();
    if (!id) return std::nullopt;
    if (!free_.empty()) {
      free_.pop_back();
    } else {
      grow_to(id->index);
      ++used_;
    }
    slot(id->index).live.store(true, std::memory_order_release);
    ++count_;
    return id;
  }

  /// The id and its copies go stale; the slot is the next to be occupied. A stale id: nothing. Writer.
  void release(SlotId id) {
    if (!is_live(id)) return;
    Slot& s = slot(id.index);
    s.live.store(false, std::memory_order_release);
    std::uint32_t next = (id.generation + 1) & generation_mask_;
    if (next < first_generation_) next = first_generation_;  // wrapped round past the first
    s.generation.store(next, std::memory_order_release);
    free_.push_back(id.index);
    --count_;
  }

  /// Whether `id` names an occupied slot at the id's generation. Any thread.
  bool is_live(SlotId id) const {
    const Slot* s = find_slot(id.index);
    return s != nullptr && s->generation.load(std::memory_order_acquire) == id.generation &&
           s->live.load(std::memory_order_acquire);
  }

  /// The item of slot `index` (< slots_used()), live or not. A reader that reads the item of an id
  /// checks is_live() before and after (the writer may release and reuse the slot in between).
  T& item(std::uint32_t index) { return slot(index).item; }
  const T& item(std::uint32_t index) const { return slot(index).item; }

  /// The item of a live id, else null. Writer (or readers of a table whose writer is locked out).
  T* find(SlotId id) { return is_live(id) ? &item(id.index) : nullptr; }
  const T* find(SlotId id) const { return is_live(id) ? &item(id.index) : nullptr; }

  /// Calls f(id, item) for every occupied slot, in index order. Writer.
  template <typename F>
  void for_each_live(F&& f) {
    for (std::uint32_t i = 0; i < used_; ++i) {
      Slot& s = slot(i);
      if (s.live.load(std::memory_order_relaxed)) f(SlotId{i, s.generation.load(std::memory_order_relaxed)}, s.item);
    }
  }

  /// The generation slot `index` (< slots_used()) is at: a live id's, or the next one's once released.
  std::uint32_t generation(std::uint32_t index) const {
    return slot(index).generation.load(std::memory_order_acquire);
  }
  /// Slots ever occupied (indices below it are valid for item() and generation()). Writer.
  std::uint32_t slots_used() const { return used_; }
  /// Slots occupied now. Writer.
  int count() const { return count_; }
  std::uint32_t capacity() const { return capacity_; }

 private:
  static constexpr std::uint32_t kChunkSlots = 256;
  struct Slot {
    std::atomic<std::uint32_t> generation{0};
    std::atomic<bool> live{false};
    T item{};
  };
  struct Chunk {
    Slot slots[kChunkSlots];
  };
  static std::size_t chunk_count(std::uint32_t capacity) { return (capacity + kChunkSlots - 1) / kChunkSlots; }

  void grow_to(std::uint32_t index) {
    std::atomic<Chunk*>& chunk = chunks_[index / kChunkSlots];
    if (chunk.load(std::memory_order_relaxed) != nullptr) return;
    auto fresh = std::make_unique<Chunk>();
    for (Slot& s : fresh->slots) s.generation.store(first_generation_, std::memory_order_relaxed);
    chunk.store(fresh.release(), std::memory_order_release);
  }
  const Slot* find_slot(std::uint32_t index) const {
    if (index >= capacity_) return nullptr;
    const Chunk* chunk = chunks_[index / kChunkSlots].load(std::memory_order_acquire);
    return chunk != nullptr ? &chunk->slots[index % kChunkSlots] : nullptr;
  }
  Slot& slot(std::uint32_t index) {
    return chunks_[index / kChunkSlots].load(std::memory_order_acquire)->slots[index % kChunkSlots];
  }
  const Slot& slot(std::uint32_t index) const {
    return chunks_[index / kChunkSlots].load(std::memory_order_acquire)->slots[index % kChunkSlots];
  }

  std::uint32_t capacity_;
  std::uint32_t generation_mask_;
  std::uint32_t first_generation_;
  std::unique_ptr<std::atomic<Chunk*>[]> chunks_;
  std::vector<std::uint32_t> free_;
  std::uint32_t used_ = 0;
  int count_ = 0;
};

}  // namespace uh::core
