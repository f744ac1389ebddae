#pragma once
// HandleTable<T>: the objects behind the C API's opaque handles (after Box2D v3's ids with a
// generation). A handle is an integer in pointer clothing, never an address: kind tag, slot
// index and the slot's generation. Freeing a slot raises its generation, so an old handle no
// longer matches and is refused instead of reaching freed memory.
//
// Threads: every member may be called from any thread (one mutex per table, held only for the
// lookup). find() hands out a shared_ptr, so an object stays alive for a call in progress on
// another thread even if its handle is closed meanwhile.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

namespace uh::capi {

template <typename T>
class HandleTable {
 public:
  /// `kind` (1..15) is stored in every handle, so that a handle of another table never matches.
  explicit HandleTable(std::uint32_t kind) : kind_(kind) {}

  /// Stores `object` and returns its new handle value, or 0 when all 2^20 slots are in use.
  std::uintptr_t insert(std::shared_ptr<T> object) {
    const std::lock_guard lock(mutex_);
    std::uint32_t index = 0;
    if (!free_.empty()) {
      index = free_.back();
      free_.pop_back();
    } else {
      if (slots_.size() >= (std::size_t{1} << kIndexBits)) return 0;
      index = static_cast<std::uint32_t>(slots_.size());
      slots_.push_back({});
    }
    Slot& slot = slots_[index];
    slot.object = std::move(object);
    return encode(index, slot.generation);
  }

  /// The object of a live handle, or null for 0, a stale handle or one of another kind.
  std::shared_ptr<T> find(std::uintptr_t handle) const {
    const std::lock_guard lock(mutex_);
    const Slot* slot = lookup(handle);
    return slot != nullptr ? slot->object : nullptr;
  }

  /// Takes the object of a live handle out of the table (the handle goes stale); null otherwise.
  std::shared_ptr<T> remove(std::uintptr_t handle) {
    const std::lock_guard lock(mutex_);
    Slot* slot = const_cast<Slot*>(lookup(handle));
    if (slot == nullptr) return nullptr;
    std::shared_ptr<T> object = std::move(slot->object);
    slot->object.reset();
    ++slot->generation;
    free_.push_back(index_of(handle));
    return object;
  }

 private:
  // handle layout (64 bits): generation (40) | index (20) | kind (4)
  static constexpr int kKindBits = 4;
  static constexpr int kIndexBits = 20;
  static_assert(sizeof(std::uintptr_t) == 8, "the C API's handles need 64-bit pointers");

  struct Slot {
    std::shared_ptr<T> object;
    std::uint64_t generation = 1;
  };

  static constexpr std::uint64_t kGenerationMask = (std::uint64_t{1} << (64 - kKindBits - kIndexBits)) - 1;

  std::uintptr_t encode(std::uint32_t index, std::uint64_t generation) const {
    return (static_cast<std::uintptr_t>(generation & kGenerationMask) << (kKindBits + kIndexBits)) |
           (static_cast<std::uintptr_t>(index) << kKindBits) | kind_;
  }
  static std::uint32_t index_of(std::uintptr_t handle) {
    return static_cast<std::uint32_t>((handle >> kKindBits) & ((1u << kIndexBits) - 1));
  }

  const Slot* lookup(std::uintptr_t handle) const {
    if ((handle & ((1u << kKindBits) - 1)) != kind_) return nullptr;
    const std::uint32_t index = index_of(handle);
    if (index >= slots_.size()) return nullptr;
    const Slot& slot = slots_[index];
    if (!slot.object || (slot.generation & kGenerationMask) != (handle >> (kKindBits + kIndexBits)))
      return nullptr;
    return &slot;
  }

  std::uint32_t kind_;
  mutable std::mutex mutex_;
  std::vector<Slot> slots_;
  std::vector<std::uint32_t> free_;
};

}  // namespace uh::capi
