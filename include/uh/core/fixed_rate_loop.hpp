#pragma once
/// \file
/// FixedRateLoop: calls a callback at a fixed rate (default 1 kHz, tested up to 8 kHz) on its own
/// thread, e.g. the haptic thread or the collision thread.
///
/// Scheduling: deadlines are absolute, `scheduled(k) = start + k * period`, so the rate does not
/// drift however long each tick takes. The loop sleeps (clock_nanosleep, absolute, timer slack
/// lowered to 1 ns) until `spin_us` before the deadline, then spins on the steady clock until the
/// deadline, then calls the callback.
///
/// Overruns: when a tick would start more than one period after its deadline (the callback or
/// the OS took too long), the loop does not run the missed ticks in a burst. It counts one missed
/// deadline, skips the missed grid points (counted in `skipped_ticks`), and runs the next tick at
/// once on the latest grid point not in the future, so the grid (phase) is kept. A tick that is
/// late by less than one period just runs late, and later ticks catch up with the grid. A loop
/// whose ticks must keep count with the clock (a simulation's steps, each a fixed stretch of its
/// time) may allow more: `catch_up_periods` N lets a tick start up to N periods late, so the ticks
/// after an overrun run back to back until they are on the grid again; only beyond N are grid
/// points skipped.
///
/// Statistics are written by the loop thread into lock-free histograms (LatencyHistogram) and
/// atomics; stats() may be called from any thread at any time and returns a plain snapshot.
///
/// Ending: the loop ends on stop(), on request_stop(), or when the callback throws (it should not;
/// the loop catches the exception, logs it and keeps its message in failure()). However it ends,
/// the exit callback given to start() runs once on the loop thread before the thread exits: the
/// place for a last action that must come from that thread, such as commanding a device to zero.
///
/// Threads: construct, start(), stop() and destroy from one controlling thread. The callback runs
/// on the loop thread only and must not call stop() (that would join itself; call request_stop()
/// instead). stats(), running() and request_stop() are callable from any thread; failure() once
/// running() is false.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <thread>

#include "uh/core/latency_histogram.hpp"
#include "uh/core/result.hpp"
#include "uh/core/tick_recorder.hpp"

namespace uh {

/// Options of a FixedRateLoop (aggregate; use designated initialisers).
struct FixedRateLoopOptions {
  double rate_hz = 1000.0;      ///< tick rate [Hz], > 0 and <= 100 kHz
  bool raise_priority = false;  ///< try SCHED_FIFO for the loop thread; failure is reported, not fatal
  int fifo_priority = 80;       ///< SCHED_FIFO priority used when raise_priority (1..99)
  double spin_us = 80.0;        ///< busy-wait this long before each deadline [us], >= 0
  std::string name = "uh-loop"; ///< thread name (first 15 characters are used by the OS)
  int catch_up_periods = 1;     ///< how late a tick may start before grid points are skipped [periods], >= 1
};

/// What the callback gets each tick.
struct TickInfo {
  std::uint64_t index = 0;                               ///< ticks run before this one (0 for the first)
  std::uint64_t grid_index = 0;                          ///< k in start + k * period (> index after skips)
  std::chrono::steady_clock::time_point scheduled_time;  ///< this tick's deadline
  std::chrono::steady_clock::time_point start_time;      ///< when the callback was entered
  double time_s = 0.0;    ///< scheduled_time - loop start [s]
  double dt_s = 0.0;      ///< start_time - previous tick's start_time [s]; the period for the first tick
  double period_s = 0.0;  ///< nominal period 1 / rate_hz [s]
};

/// Snapshot of a FixedRateLoop's statistics since its last start(). Plain data.
struct FixedRateLoopStats {
  std::uint64_t ticks = 0;             ///< callbacks run
  std::uint64_t missed_deadlines = 0;  ///< ticks that would have started more than catch_up_periods late
  std::uint64_t skipped_ticks = 0;     ///< grid points dropped when re-anchoring after misses
  double rate_hz = 0.0;                ///< nominal rate [Hz]
  double achieved_rate_hz = 0.0;       ///< (ticks - 1) / (last start - first start) [Hz]; 0 before 2 ticks
  double elapsed_s = 0.0;              ///< last tick start - first tick start [s]
  /// |actual interval between consecutive tick starts - period| [ns] (period jitter).
  LatencySummary period_error;
  /// start_time - scheduled_time [ns] (wake-up lateness, >= 0).
  LatencySummary lateness;
  /// time spent in the callback [ns].
  LatencySummary callback_duration;
  bool running = false;          ///< the loop thread is running
  bool priority_raised = false;  ///< SCHED_FIFO was granted (only tried when raise_priority)
};

/// How a loop ended, as its exit callback sees it.
struct LoopExit {
  bool callback_threw = false;  ///< the tick callback threw (else a stop was requested)
  const char* what = "";        ///< the exception's message when it threw ("" otherwise); valid during the call
};

class FixedRateLoop {
 public:
  using Callback = std::function<void(const TickInfo&)>;
  using ExitCallback = std::function<void(const LoopExit&)>;

  explicit FixedRateLoop(FixedRateLoopOptions options = {});
  /// Stops and joins the loop thread if it runs.
  ~FixedRateLoop();
  FixedRateLoop(const FixedRateLoop&) = delete;
  FixedRateLoop& operator=(const FixedRateLoop&) = delete;

  /// Resets the statistics and starts the loop thread calling `callback` every period; the first
  /// tick is scheduled one period after start(). `on_exit` (optional) runs once on the loop thread
  /// when the loop ends, for any reason, before the thread exits (an exception from it is caught
  /// and logged). Returns an error (and starts nothing) if the loop is already running, the
  /// callback is empty or the options are invalid. Controlling thread only; not real-time safe. A
  /// stopped loop may be started again.
  Status start(Callback callback, ExitCallback on_exit = {});

  /// Asks the loop to stop and joins its thread; the current tick finishes first. Idempotent.
  /// Controlling thread only, never from the callback.
  void stop();

  /// Asks the loop to stop after the current tick, without waiting. Any thread, including the
  /// callback; real-time safe. stop() (or the destructor) still joins the thread.
  void request_stop();

  /// True from start() until the loop thread has finished (after stop() or request_stop()). Any thread.
  [[nodiscard]] bool running() const;

  /// Lock-free snapshot of the statistics. Any thread; not real-time safe (reads ~30 KB).
  [[nodiscard]] FixedRateLoopStats stats() const;
  /// Missed deadlines since the last start() (FixedRateLoopStats::missed_deadlines) without the
  /// cost of stats(). Any thread; real-time safe.
  [[nodiscard]] std::uint64_t missed_deadlines() const {
    return missed_deadlines_.load(std::memory_order_relaxed);
  }

  /// Why the last run ended, if the callback threw: "the tick callback threw: <message>"; empty
  /// after a requested stop. Read once running() is false (or after stop()); controlling thread.
  [[nodiscard]] const std::string& failure() const { return failure_; }

  [[nodiscard]] const FixedRateLoopOptions& options() const { return options_; }

 private:
  void run(Callback callback, ExitCallback on_exit);

  FixedRateLoopOptions options_;
  std::thread thread_;
  std::string failure_;  // written by the loop thread before running_ turns false
  std::atomic<bool> stop_requested_{false};
  std::atomic<bool> running_{false};
  std::atomic<bool> priority_raised_{false};
  std::atomic<std::uint64_t> missed_deadlines_{0};
  std::atomic<std::uint64_t> skipped_ticks_{0};
  TickRecorder recorder_;
};

}  // namespace uh
