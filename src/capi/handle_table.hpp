#pragma once
// HandleTable<T>: the objects behind the C API's ids (after Box2D v3's ids with a generation). An
// id is a 64-bit integer passed by value, never an address: kind tag, slot index and the slot's
// generation. Destroying a slot raises its generation, so an old id no longer matches and is
// refused instead of reaching freed memory. Ids need no 64-bit pointers: 32-bit builds use them as
// they are.
//
// Threads: every member may be called from any thread (one mutex per table, held only for the
// lookup). find() hands out a shared_ptr, so an object stays alive for a call in progress on
// another thread even if its id is destroyed meanwhile.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

namespace uh::capi {

template <typename T>
class HandleTable {
 public:
  /// `kind` (1..255) is stored in every id, so that an id of another table never matches.
  explicit HandleTable(std::uint8_t kind) : kind_(kind) {}

  /// Stores `object` and returns its new id, or 0 when all 2^20 slots are in use.
  std::uint64_t insert(std::shared_ptr<T> object) {
    const std::lock_guard lock(mutex_);
    std::uint32_t index = 0;
    if (!free_.empty()) {
      index = free_.back();
      free_.pop_back();
    } else {
      if (slots_.size() >= kMaxSlots) return 0;
      index = static_cast<std::uint32_t>(slots_.size());
      slots_.push_back({});
    }
    Slot& slot = slots_[index];
    slot.object = std::move(object);
    return encode(index, slot.generation);
  }

  /// The object of a live id, or null for 0, a stale id or one of another kind.
  std::shared_ptr<T> find(std::uint64_t id) const {
    const std::lock_guard lock(mutex_);
    const Slot* slot = lookup(id);
    return slot != nullptr ? slot->object : nullptr;
  }

  /// Takes the object of a live id out of the table (the id goes stale); null otherwise.
  std::shared_ptr<T> remove(std::uint64_t id) {
    const std::lock_guard lock(mutex_);
    Slot* slot = const_cast<Slot*>(lookup(id));
    if (slot == nullptr) return nullptr;
    std::shared_ptr<T> object = std::move(slot->object);
    slot->object.reset();
    slot->generation = (slot->generation + 1) & kGenerationMask;
    free_.push_back(index_of(id));
    return object;
  }

 private:
  // id layout (64 bits): kind (8) | generation (24) | index (32); 0 is never an id (kind >= 1)
  static constexpr std::size_t kMaxSlots = std::size_t{1} << 20;
  static constexpr std::uint32_t kGenerationMask = (1u << 24) - 1;

  struct Slot {
    std::shared_ptr<T> object;
    std::uint32_t generation = 1;
  };

  std::uint64_t encode(std::uint32_t index, std::uint32_t generation) const {
    return (std::uint64_t{kind_} << 56) | (std::uint64_t{generation} << 32) | index;
  }
  static std::uint32_t index_of(std::uint64_t id) { return static_cast<std::uint32_t>(id & 0xffffffffu); }

  const Slot* lookup(std::uint64_t id) const {
    if ((id >> 56) != kind_) return nullptr;
    const std::uint32_t index = index_of(id);
    if (index >= slots_.size()) return nullptr;
    const Slot& slot = slots_[index];
    if (!slot.object || slot.generation != ((id >> 32) & kGenerationMask)) return nullptr;
    return &slot;
  }

  std::uint8_t kind_;
  mutable std::mutex mutex_;
  std::vector<Slot> slots_;
  std::vector<std::uint32_t> free_;
};

}  // namespace uh::capi
