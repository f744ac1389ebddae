#pragma once
/// \file
/// Sleeping until an atomic word changes: the project's one way of doing what std::atomic's
/// wait() and notify_one() do. On Linux they are exactly those (a futex, no lock on either side).
/// On Windows they are WaitOnAddress and WakeByAddressSingle (Windows 8 and later): the libstdc++
/// of Debian's mingw-w64 (GCC 12) implements std::atomic::wait, and with it std::binary_semaphore
/// and std::stop_callback's wait, with a condition variable that loses a wake-up posted between
/// its check of the value and its wait (GCC bug 106183); a C API test hung there under wine.

#include <atomic>
#include <cstdint>

namespace uh {

/// Blocks the calling thread while `word` holds `old`. It may return early (callers re-check).
void wait_while_equal(const std::atomic<std::uint32_t>& word, std::uint32_t old);

/// Wakes one thread blocked in wait_while_equal() on `word`. No lock, no allocation: one system
/// call, so a real-time thread may post with it.
void wake_one(std::atomic<std::uint32_t>& word);

}  // namespace uh
