#pragma once
/// \file
/// raise_max: the running maximum of a figure one thread writes and others read (the haptic or
/// collision thread's statistics, read by the monitor). One writer, so a load and a store suffice
/// (no compare-exchange loop); relaxed, since the value orders nothing else. Real-time safe.

#include <atomic>

namespace uh {

template <typename T>
void raise_max(std::atomic<T>& max, T value) {
  if (value > max.load(std::memory_order_relaxed)) max.store(value, std::memory_order_relaxed);
}

}  // namespace uh
