#include "uh/forcecomp/force_safety.hpp"

#include <cmath>

namespace uh::forcecomp {

namespace {

void bump(std::atomic<std::uint64_t>& counter) {
  // single writer (the haptic thread): a relaxed load and store is enough and never locks
  counter.store(counter.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
}

}  // namespace

Wrench ForceSafety::apply(const Wrench& raw, double now_s, double data_time_s) {
  bump(ticks_);
  // read the stop/fault state before the resume request: resume() publishes the request before it
  // clears the stop, so a tick that sees the stop cleared also sees the request (no one-tick spike)
  const bool zero = stopped_.load(std::memory_order_acquire) || faulted_.load(std::memory_order_acquire);
  if (resume_requested_.exchange(false, std::memory_order_acq_rel)) watchdog_.reset(0.0);

  Wrench w = raw;
  if (!is_finite(w.force) || !is_finite(w.torque)) {
    // a NaN anywhere means the whole computation is suspect: drop both parts
    bump(nonfinite_);
    w = Wrench{};
  }
  const double gain = watchdog_.update(now_s, data_time_s);
  if (watchdog_.stale()) bump(stale_ticks_);
  w.force *= gain;
  w.torque *= gain;
  if (zero) {
    bump(zeroed_ticks_);
    return Wrench{};
  }
  return w;
}

void ForceSafety::resume() {
  resume_requested_.store(true, std::memory_order_release);
  faulted_.store(false, std::memory_order_release);
  stopped_.store(false, std::memory_order_release);
}

ForceSafetyCounters ForceSafety::counters() const {
  ForceSafetyCounters c;
  c.ticks = ticks_.load(std::memory_order_relaxed);
  c.nonfinite = nonfinite_.load(std::memory_order_relaxed);
  c.stale_ticks = stale_ticks_.load(std::memory_order_relaxed);
  c.zeroed_ticks = zeroed_ticks_.load(std::memory_order_relaxed);
  return c;
}

}  // namespace uh::forcecomp
