// WaitOnAddress is declared from Windows 8 on
#if !defined(_WIN32_WINNT) || _WIN32_WINNT < 0x0602
#undef _WIN32_WINNT
#define _WIN32_WINNT 0x0602
#endif
#include <windows.h>

#include "uh/core/address_wait.hpp"

namespace uh {
namespace {

// std::atomic<std::uint32_t> holds its value as a plain 32-bit word (static_asserted below)
volatile void* address_of(const std::atomic<std::uint32_t>& word) {
  return const_cast<volatile void*>(static_cast<const volatile void*>(&word));
}
static_assert(sizeof(std::atomic<std::uint32_t>) == sizeof(std::uint32_t));

}  // namespace

void wait_while_equal(const std::atomic<std::uint32_t>& word, std::uint32_t old) {
  // WaitOnAddress compares under the kernel's own lock: a wake between a caller's check and
  // this call is not lost (it returns at once when the word already differs)
  WaitOnAddress(address_of(word), &old, sizeof old, INFINITE);
}

void wake_one(std::atomic<std::uint32_t>& word) { WakeByAddressSingle(const_cast<void*>(address_of(word))); }

}  // namespace uh
