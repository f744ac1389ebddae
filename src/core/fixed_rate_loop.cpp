#include "uh/core/fixed_rate_loop.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <string>
#include <utility>

#include "loop_thread.hpp"
#include "uh/core/log.hpp"

namespace uh {
namespace {

using Clock = std::chrono::steady_clock;
using Nanos = std::chrono::nanoseconds;

// the longest single sleep, so that request_stop() is noticed even at very low rates
constexpr Nanos kMaxSleepChunk = std::chrono::milliseconds(10);

inline void cpu_relax() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#elif defined(__aarch64__)
  asm volatile("yield");
#endif
}

}  // namespace

FixedRateLoop::FixedRateLoop(FixedRateLoopOptions options) : options_(std::move(options)) {}

FixedRateLoop::~FixedRateLoop() { stop(); }

Status FixedRateLoop::start(Callback callback, ExitCallback on_exit) {
  if (running_.load(std::memory_order_acquire)) {
    return Error{"loop '" + options_.name + "': already running"};
  }
  if (!callback) return Error{"loop '" + options_.name + "': no callback to run"};
  if (!std::isfinite(options_.rate_hz) || options_.rate_hz <= 0.0 || options_.rate_hz > 100'000.0) {
    return Error{"loop '" + options_.name + "': rate_hz = " + std::to_string(options_.rate_hz) +
                 " is out of range (expected 0 < rate_hz <= 100000)"};
  }
  if (options_.catch_up_periods < 1) {
    return Error{"loop '" + options_.name + "': catch_up_periods = " + std::to_string(options_.catch_up_periods) +
                 " is out of range (expected >= 1)"};
  }
  if (!std::isfinite(options_.spin_us) || options_.spin_us < 0.0) {
    return Error{"loop '" + options_.name + "': spin_us = " + std::to_string(options_.spin_us) +
                 " is invalid (expected a finite value >= 0)"};
  }
  if (options_.raise_priority && (options_.fifo_priority < 1 || options_.fifo_priority > 99)) {
    return Error{"loop '" + options_.name + "': fifo_priority = " + std::to_string(options_.fifo_priority) +
                 " is out of range (expected 1..99)"};
  }
  // a loop that ended through request_stop() still has a thread to join
  if (thread_.joinable()) thread_.join();

  stop_requested_.store(false, std::memory_order_relaxed);
  failure_.clear();
  priority_raised_.store(false, std::memory_order_relaxed);
  missed_deadlines_.store(0, std::memory_order_relaxed);
  skipped_ticks_.store(0, std::memory_order_relaxed);
  recorder_.reset();

  running_.store(true, std::memory_order_release);
  try {
    thread_ = std::thread([this, cb = std::move(callback), exit_cb = std::move(on_exit)]() mutable {
      run(std::move(cb), std::move(exit_cb));
    });
  } catch (const std::exception& e) {
    running_.store(false, std::memory_order_release);
    return Error{"loop '" + options_.name + "': cannot create its thread: " + e.what(), ErrorKind::kThread};
  }
  return Ok{};
}

void FixedRateLoop::stop() {
  stop_requested_.store(true, std::memory_order_release);
  if (thread_.joinable()) {
    assert(thread_.get_id() != std::this_thread::get_id() &&
           "uh::FixedRateLoop::stop(): called from the loop's own callback; use request_stop()");
    thread_.join();
  }
}

void FixedRateLoop::request_stop() { stop_requested_.store(true, std::memory_order_release); }

bool FixedRateLoop::running() const { return running_.load(std::memory_order_acquire); }

FixedRateLoopStats FixedRateLoop::stats() const {
  FixedRateLoopStats s;
  recorder_.fill(s);
  s.missed_deadlines = missed_deadlines_.load(std::memory_order_relaxed);
  s.skipped_ticks = skipped_ticks_.load(std::memory_order_relaxed);
  s.rate_hz = options_.rate_hz;
  s.running = running();
  s.priority_raised = priority_raised_.load(std::memory_order_relaxed);
  return s;
}

void FixedRateLoop::run(Callback callback, ExitCallback on_exit) {
  detail::LoopThread os_thread(options_.name);
  if (options_.raise_priority) {
    const std::string refused = os_thread.raise_priority(options_.fifo_priority);
    priority_raised_.store(refused.empty(), std::memory_order_relaxed);
    // still before the first tick, so the loop thread may log here
    if (!refused.empty()) {
      log::warn("FixedRateLoop '{}': real-time priority refused: {}; running at normal priority",
                options_.name, refused);
    }
  }

  const Nanos period(static_cast<std::int64_t>(std::llround(1e9 / options_.rate_hz)));
  const Nanos spin(static_cast<std::int64_t>(std::llround(options_.spin_us * 1e3)));
  const Clock::time_point origin = Clock::now();
  std::uint64_t grid = 1;
  Clock::time_point scheduled = origin + period;
  Clock::time_point previous_start{};
  std::uint64_t index = 0;

  TickInfo info;
  info.period_s = static_cast<double>(period.count()) * 1e-9;
  LoopExit exit;
  std::string thrown;  // the exception's message, kept past its catch block for on_exit

  try {
    while (!stop_requested_.load(std::memory_order_acquire)) {
      // sleep in chunks (so that a stop request is seen), then spin the last stretch
      const Clock::time_point wake = scheduled - spin;
      for (Clock::time_point now = Clock::now(); now < wake; now = Clock::now()) {
        os_thread.sleep_until(std::min(wake, now + kMaxSleepChunk));
        if (stop_requested_.load(std::memory_order_acquire)) break;
      }
      if (stop_requested_.load(std::memory_order_acquire)) break;
      Clock::time_point now = Clock::now();
      while (now < scheduled) {
        cpu_relax();
        now = Clock::now();
      }

      // re-anchor instead of bursting: skip the grid points that are more than a period past (or
      // more than the catch-up the options allow)
      const Nanos late = now - scheduled;
      if (late > period * options_.catch_up_periods) {
        const std::int64_t skipped = late.count() / period.count();
        grid += static_cast<std::uint64_t>(skipped);
        scheduled += period * skipped;
        missed_deadlines_.fetch_add(1, std::memory_order_relaxed);
        skipped_ticks_.fetch_add(static_cast<std::uint64_t>(skipped), std::memory_order_relaxed);
      }

      info.index = index;
      info.grid_index = grid;
      info.scheduled_time = scheduled;
      info.start_time = now;
      info.time_s = std::chrono::duration<double>(scheduled - origin).count();
      info.dt_s = index == 0 ? info.period_s : std::chrono::duration<double>(now - previous_start).count();
      callback(info);
      recorder_.record(scheduled, now, Clock::now(), period);

      previous_start = now;
      ++index;
      ++grid;
      scheduled += period;
    }
  } catch (const std::exception& e) {
    thrown = e.what();
    exit.callback_threw = true;
  } catch (...) {
    thrown = "an exception of unknown type";
    exit.callback_threw = true;
  }
  if (exit.callback_threw) {
    failure_ = "the tick callback threw: " + thrown;
    exit.what = thrown.c_str();
  }
  // the exit callback first (it may have to zero a device at once), then the log
  if (on_exit) {
    try {
      on_exit(exit);
    } catch (const std::exception& e) {
      log::error("FixedRateLoop '{}': the exit callback threw ({})", options_.name, e.what());
    } catch (...) {
      log::error("FixedRateLoop '{}': the exit callback threw", options_.name);
    }
  }
  if (exit.callback_threw) log::error("FixedRateLoop '{}': {}; the loop stopped", options_.name, failure_);
  running_.store(false, std::memory_order_release);
}

}  // namespace uh
