#pragma once
/// \file
/// HapticManager: owns a device and the haptic thread; broadcasts MoveOnHapticTick and
/// ForceOnHapticTick every tick and sends the summed force through a safety stage to the device.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "uh/core/delegator.hpp"
#include "uh/core/event_counter.hpp"
#include "uh/core/fixed_rate_loop.hpp"
#include "uh/core/result.hpp"
#include "uh/core/spsc_queue.hpp"
#include "uh/haptico/force_limiter.hpp"
#include "uh/haptico/haptic_device.hpp"
#include "uh/haptico/servo_clock.hpp"
#include "uh/haptico/trace_sample.hpp"

namespace uh::haptico {

/// Devices that stop together (the managers of one session's tools): a device fault latched by
/// one member, or its haptic thread ending by a throw, zeroes every member's force from that
/// member's next tick on (each device has its own clock, so "at once" is within one period of
/// each loop). It stays tripped. Any thread; real-time safe; outlives its managers.
class FaultGroup {
 public:
  void trip() { tripped_.store(true, std::memory_order_release); }
  bool tripped() const { return tripped_.load(std::memory_order_acquire); }

 private:
  std::atomic<bool> tripped_{false};
};

/// Options of a HapticManager (options aggregate).
struct HapticManagerOptions {
  double rate_hz = 1000.0;          ///< haptic tick rate [Hz], in (0, 10000]; devices run 1-4 kHz
  bool raise_priority = false;      ///< ask for SCHED_FIFO for the haptic thread (see FixedRateLoop)
  /// Busy-wait this long before each tick's deadline [us] (FixedRateLoopOptions::spin_us): a longer
  /// spin absorbs longer wake-up latencies of the OS at the cost of that much CPU per tick.
  double spin_us = 80.0;
  std::size_t trace_capacity = 0;   ///< ticks the trace queue holds between drains; 0 = no trace
  /// Time [s] over which forces fade in after open(), start(), resume() and clear_fault(), so that a tool
  /// that starts inside an object does not jolt the hand; counted in ticks at rate_hz (also in
  /// stepped sessions). 0 disables the fade.
  double soft_start_s = 0.05;
  /// Consecutive ticks whose DeviceState::time_s does not advance before the device counts as
  /// frozen (a stalled driver repeating an old pose): treated as a device error. 0 disables.
  int max_frozen_ticks = 50;
  /// The tool's and the session's limits and the rate limit, applied with the device's own limits
  /// by one ForceLimiter (default: no tool or safety limit, the default rate limit).
  ForceLimitOptions limits{};
  /// The group this device stops with (not owned; null: it stops alone). See FaultGroup.
  FaultGroup* fault_group = nullptr;
};

/// Ticks in which each limit of the chain engaged (ForceLimiter); plain data.
struct LimitCounters {
  std::uint64_t device = 0;  ///< the device's limit was the smallest and clamped force or torque
  std::uint64_t tool = 0;    ///< the tool's limit was the smallest and clamped
  std::uint64_t safety = 0;  ///< the session's safety limit was the smallest and clamped
  std::uint64_t rate = 0;    ///< the rate limit bounded the change from the previous tick
};

/// Counters of a HapticManager; a snapshot, plain data.
struct HapticStats {
  FixedRateLoopStats loop{};          ///< timing of the haptic thread (zero in stepped sessions)
  std::uint64_t ticks = 0;            ///< ticks run (threaded and stepped)
  std::uint64_t force_clamped = 0;    ///< ticks whose force was scaled down to the smallest limit
  std::uint64_t torque_clamped = 0;   ///< ticks whose torque was scaled down to the smallest limit
  LimitCounters limits{};             ///< which limit engaged how often
  std::uint64_t nonfinite = 0;        ///< ticks whose requested command had a NaN/inf (zero sent)
  std::uint64_t device_errors = 0;    ///< ticks whose read_state() failed
  std::uint64_t zeroed_ticks = 0;     ///< ticks that sent zero because of halt() or a fault
  std::uint64_t trace_dropped = 0;    ///< trace samples lost because the queue was full
  bool faulted = false;               ///< a device error is latched (see clear_fault())
  bool halted = false;                ///< halt() is in effect
};

/// Runs the haptic loop for one device. Every tick, on the haptic thread:
///   1. state = device.read_state(); an error status, or a time_s that has not advanced for
///      max_frozen_ticks ticks, is a device error;
///   2. MoveOnHapticTick.broadcast(state)            (e.g. move the tool in the scene);
///   3. ForceOnHapticTick.broadcast(state, command)  (each delegate adds its force to `command`,
///      which starts at zero);
///   4. safety: a NaN/inf anywhere -> zero (counted); torque zeroed on 3-DOF devices; zero while
///      halted, after a device error (latched until clear_fault()) or once the FaultGroup
///      tripped (another device's fault); otherwise the limit chain
///      (ForceLimiter): force and torque scaled down to the smallest of the device's, the tool's
///      and the safety limits, a linear fade-in over soft_start_s after open(), start(), resume()
///      and clear_fault(), and the rate limit on the change from the previous tick. Zero is sent
///      at once, never rate-limited; each engaged limit is counted (stats().limits);
///   5. device.command(command); the tick is pushed to the trace queue if enabled;
///   6. SentOnHapticTick.broadcast(sample)  (what was read, asked for and sent this tick).
/// The same tick code runs in threaded sessions (start()/stop()) and stepped ones (step()). The
/// haptic thread is the manager's own FixedRateLoop, or for a ClockedDevice (OpenHaptics) the
/// vendor's servo thread: the tick then runs inside the device's servo frame, the device is the
/// clock, and stats().loop describes the device's frames.
///
/// Frames and units: those of the device (DeviceState, DeviceCommand), SI.
///
/// Ending: however the haptic thread ends (stop(), or a tick that threw: a delegate or the
/// driver), its last act is to command zero force and trace that zero (kTraceStopped); a thread
/// that ended by a throw keeps the cause in thread_status(). A stepped session gets its zero from
/// stop(). stop() and the destructor always leave the device at zero.
///
/// Threads: construct, open(), start(), stop(), step(), bind delegates and destroy from one
/// controlling thread. Bind delegates only while no threaded session runs (the Delegator is not
/// a cross-thread primitive; start() publishes the bindings to the haptic thread): from start()
/// to stop() binding is refused (an invalid handle or empty connection, an error logged, see
/// Delegator::refuse_binding). Delegates run on the haptic thread and must be real-time safe. halt(),
/// resume(), clear_fault(), stats() and running() may be called from any thread; drain_trace() from one
/// consumer thread.
class HapticManager {
 public:
  /// Takes ownership of `device` (not null). Allocates the trace queue. Not real-time safe.
  explicit HapticManager(std::unique_ptr<HapticDevice> device, const HapticManagerOptions& options = {});
  /// Stops the haptic thread, sends zero force and closes the device.
  ~HapticManager();
  HapticManager(const HapticManager&) = delete;
  HapticManager& operator=(const HapticManager&) = delete;

  /// Opens the device and checks its description (an actuated device must report positive force
  /// limits). Idempotent. An Error names the device and the problem.
  Status open();
  /// Opens the device if needed and starts the haptic thread at options().rate_hz.
  Status start();
  /// Stops the haptic thread (the current tick finishes; the thread commands zero as it ends), or
  /// after stepped ticks commands zero itself; the zero is traced. The device stays open; start()
  /// or step() may follow. Idempotent.
  void stop();
  /// Why the last threaded run ended: an Error naming the cause ("the haptic thread stopped:
  /// a ForceOnHapticTick delegate (computing the force) threw: ...") once the thread ended because
  /// a tick threw; Ok while it runs, after a requested stop, and before any run. Controlling thread.
  Status thread_status() const;
  /// Whether a device fault is latched: the device reported an error or stopped advancing, and
  /// gets zero until clear_fault(). Any thread; real-time safe.
  bool faulted() const { return faulted_.load(std::memory_order_acquire); }
  /// Ok, or while a device fault is latched an Error naming the device and why, in the driver's
  /// words (HapticDevice::fault_reason()), e.g. "device 'forcedimension omega.3' faulted: sending
  /// the force (dhdSetForce): communication error; it was sent zero force". Controlling thread.
  Status device_status();
  /// Runs one tick now on the calling thread, with `now_s` [s] as the tick time: the deterministic
  /// entry for stepped sessions and tests. The device must be open and no threaded session may
  /// run (asserted). Returns what happened in that tick.
  TraceSample step(double now_s);

  /// Sends zero force from the next tick on, whatever the delegates ask, until resume(). Any
  /// thread; real-time safe.
  void halt() { halted_.store(true, std::memory_order_release); }
  /// Ends a halt(). Any thread.
  void resume() {
    restart_fade_.store(true, std::memory_order_release);
    halted_.store(false, std::memory_order_release);
  }
  /// Clears a latched device fault so that forces fade in again. Any thread.
  void clear_fault() {
    restart_fade_.store(true, std::memory_order_release);
    faulted_.store(false, std::memory_order_release);
  }
  /// Binding side of SentOnHapticTick(const TraceSample&): the tick as sent to the device, after
  /// the safety stage (e.g. to publish the newest state to another thread). See the thread rules.
  DelegateSink<const TraceSample&> sent_on_haptic_tick() { return DelegateSink{sent_event_}; }

  /// Binding side of MoveOnHapticTick(const DeviceState&). See the thread rules above: refused
  /// while the haptic thread runs.
  DelegateSink<const DeviceState&> move_on_haptic_tick() { return DelegateSink{move_event_}; }
  /// Binding side of ForceOnHapticTick(const DeviceState&, DeviceCommand&): add to the command.
  /// Refused while the haptic thread runs.
  DelegateSink<const DeviceState&, DeviceCommand&> force_on_haptic_tick() { return DelegateSink{force_event_}; }

  /// Time of the tick being run [s]: in threaded sessions the steady-clock time of the tick's start
  /// (seconds since the steady clock's epoch, the clock of ContactFrame::time_s); in stepped ones
  /// the `now_s` given to step(). For delegates (haptic thread) during a tick.
  double tick_time_s() const { return tick_time_s_; }

  /// Moves the recorded ticks out of the trace queue into `out` (appends); returns how many.
  /// One consumer thread; not real-time safe.
  std::size_t drain_trace(std::vector<TraceSample>& out);
  /// Same, writing CSV rows (see write_trace_row) to `csv`.
  std::size_t drain_trace(std::ostream& csv);

  HapticStats stats() const;
  /// Missed deadlines of the haptic thread since start(), without the cost of stats(). Any
  /// thread; real-time safe (so a delegate may read it during a tick).
  std::uint64_t missed_deadlines() const;
  /// Ticks run (HapticStats::ticks) without the cost of stats(). Any thread; real-time safe.
  std::uint64_t ticks() const { return ticks_.load(); }
  bool running() const;
  bool is_open() const { return open_; }
  /// The device's description as read by open().
  const DeviceInfo& device_info() const { return info_; }
  /// The device itself, e.g. for a driver's own counters (their thread rules apply).
  const HapticDevice& device() const { return *device_; }
  /// The limit chain built by open() from the device's and options().limits (controlling thread,
  /// while no threaded session runs).
  const ForceLimiter& limiter() const { return limiter_; }
  const HapticManagerOptions& options() const { return options_; }

 private:
  // where the haptic thread is in its tick, for the message when something in it throws
  enum class TickPhase { kIdle, kReadState, kMove, kForce, kCommand, kSent };
  static const char* phase_name(TickPhase phase);

  TraceSample tick(double now_s);
  void count(std::uint32_t flags);
  // latches a device fault here and trips the fault group (any thread)
  void latch_fault();
  void on_loop_exit(const LoopExit& exit);
  void allow_binding();
  // commands zero, restarts the limit chain from it and traces it (with the state read after it
  // when `read_device`) as the run's last sample
  void send_final_zero(double now_s, bool read_device);

  HapticManagerOptions options_;
  std::unique_ptr<HapticDevice> device_;
  DeviceInfo info_{};
  ForceLimiter limiter_{};  // haptic thread while running
  bool open_ = false;
  FixedRateLoop loop_;
  ServoClock* servo_ = nullptr;  // the device's own clock (a ClockedDevice), else loop_ ticks
  Delegator<const DeviceState&> move_event_;
  Delegator<const DeviceState&, DeviceCommand&> force_event_;
  Delegator<const TraceSample&> sent_event_;
  std::unique_ptr<SpscQueue<TraceSample>> trace_;
  double tick_time_s_ = 0.0;
  TickPhase phase_ = TickPhase::kIdle;  // haptic thread
  DeviceState last_state_{};            // haptic thread: the state of the last tick
  bool ended_with_zero_ = false;        // no tick since the last final zero
  bool servo_run_started_ = false;      // a run on the device's clock started and stop() has not seen it end
  std::string failure_;                 // written by the haptic thread as it ends (thread_status())
  std::int64_t fade_count_ = 0;
  int frozen_ticks_ = 0;          // consecutive ticks with the same device time (haptic thread)
  double last_device_time_s_ = 0.0;
  bool has_device_time_ = false;  // ticks since the fade-in restarted (haptic thread)
  double fade_ticks_ = 1.0;      // ticks the fade-in takes, >= 1
  std::atomic<bool> restart_fade_{false};
  std::atomic<bool> halted_{false};
  std::atomic<bool> faulted_{false};
  std::atomic<bool> fault_was_freeze_{false};  // the latched fault is a device time that stopped advancing
  EventCounter ticks_;
  EventCounter force_clamped_;
  EventCounter torque_clamped_;
  EventCounter device_limited_;
  EventCounter tool_limited_;
  EventCounter safety_limited_;
  EventCounter rate_limited_;
  EventCounter nonfinite_;
  EventCounter device_errors_;
  EventCounter zeroed_ticks_;
  EventCounter trace_dropped_;
};

}  // namespace uh::haptico
