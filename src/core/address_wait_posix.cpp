#include "uh/core/address_wait.hpp"

namespace uh {

void wait_while_equal(const std::atomic<std::uint32_t>& word, std::uint32_t old) {
  word.wait(old, std::memory_order_acquire);
}

void wake_one(std::atomic<std::uint32_t>& word) { word.notify_one(); }

}  // namespace uh
