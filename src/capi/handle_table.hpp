#pragma once
// HandleTable<T>: the objects behind the C API's ids, in core's slot table with generations. An
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
#include <optional>

#include "uh/core/slot_table.hpp"

namespace uh::capi {

template <typename T>
class HandleTable {
 public:
  /// `kind` (1..255) is stored in every id, so that an id of another table never matches.
  explicit HandleTable(std::uint8_t kind) : kind_(kind) {}

  /// Stores `object` and returns its new id, or 0 when all 2^20 slots are in use.
  std::uint64_t insert(std::shared_ptr<T> object) {
    const std::lock_guard lock(mutex_);
    const std::optional<core::SlotId> id = slots_.occupy();
    if (!id) return 0;
    slots_.item(id->index) = std::move(object);
    return encode(*id);
  }

  /// The object of a live id, or null for 0, a stale id or one of another kind.
  std::shared_ptr<T> find(std::uint64_t id) const {
    const std::lock_guard lock(mutex_);
    const std::shared_ptr<T>* object = (id >> 56) == kind_ ? slots_.find(decode(id)) : nullptr;
    return object != nullptr ? *object : nullptr;
  }

  /// Takes the object of a live id out of the table (the id goes stale); null otherwise.
  std::shared_ptr<T> remove(std::uint64_t id) {
    const std::lock_guard lock(mutex_);
    std::shared_ptr<T>* slot = (id >> 56) == kind_ ? slots_.find(decode(id)) : nullptr;
    if (slot == nullptr) return nullptr;
    std::shared_ptr<T> object = std::move(*slot);
    slot->reset();
    slots_.release(decode(id));
    return object;
  }

 private:
  // id layout (64 bits): kind (8) | generation (24) | index (32); 0 is never an id (kind >= 1)
  static constexpr std::uint32_t kMaxSlots = std::uint32_t{1} << 20;
  static constexpr std::uint32_t kGenerationMask = (1u << 24) - 1;

  std::uint64_t encode(core::SlotId id) const {
    return (std::uint64_t{kind_} << 56) | (std::uint64_t{id.generation} << 32) | id.index;
  }
  static core::SlotId decode(std::uint64_t id) {
    return {static_cast<std::uint32_t>(id & 0xffffffffu), static_cast<std::uint32_t>(id >> 32) & kGenerationMask};
  }

  std::uint8_t kind_;
  mutable std::mutex mutex_;
  core::SlotTable<std::shared_ptr<T>> slots_{kMaxSlots, kGenerationMask};
};

}  // namespace uh::capi
