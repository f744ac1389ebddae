#include "uh/haptico/haptic_manager.hpp"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <fmt/format.h>
#include <utility>

namespace uh::haptico {

namespace {

bool finite(const DeviceCommand& c) { return is_finite(c.force) && is_finite(c.torque); }

constexpr const char* kMoveBindRefused =
    "haptic manager: MoveOnHapticTick delegates cannot be bound while the haptic thread runs; bind before start() "
    "or after stop()";
constexpr const char* kForceBindRefused =
    "haptic manager: ForceOnHapticTick delegates cannot be bound while the haptic thread runs; bind before "
    "start() or after stop()";
constexpr const char* kSentBindRefused =
    "haptic manager: SentOnHapticTick delegates cannot be bound while the haptic thread runs; bind before "
    "start() or after stop()";

double steady_now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

FixedRateLoopOptions loop_options(const HapticManagerOptions& o) {
  FixedRateLoopOptions l;
  l.rate_hz = o.rate_hz;
  l.raise_priority = o.raise_priority;
  l.spin_us = o.spin_us;
  l.name = "uh-haptic";
  return l;
}

}  // namespace

HapticManager::HapticManager(std::unique_ptr<HapticDevice> device, const HapticManagerOptions& options)
    : options_(options), device_(std::move(device)), loop_(loop_options(options)) {
  assert(device_ != nullptr && "uh::haptico::HapticManager::HapticManager(): device must not be null");
  // a device that brings its own servo thread is the clock: the tick runs in its frames
  if (auto* clocked = dynamic_cast<ClockedDevice*>(device_.get()); clocked != nullptr)
    servo_ = &clocked->servo_clock();
  const double fade_ticks = options_.soft_start_s * options_.rate_hz;
  fade_ticks_ = fade_ticks > 1.0 && std::isfinite(fade_ticks) ? fade_ticks : 1.0;
  if (options_.trace_capacity > 0) trace_ = std::make_unique<SpscQueue<TraceSample>>(options_.trace_capacity);
}

HapticManager::~HapticManager() {
  stop();
  if (open_) {
    const Status closed = device_->close();
    (void)closed;  // nothing left to report to at destruction
  }
}

Status HapticManager::open() {
  if (open_) return Ok{};
  if (Status s = device_->open(); !s) return s.error().classified(ErrorKind::kDevice);
  info_ = device_->info();
  const auto refuse = [this](std::string why) -> Status {
    const Status closed = device_->close();
    (void)closed;
    return Error{fmt::format("device '{}': {}", info_.name, why), ErrorKind::kDevice};
  };
  if (info_.dof_actuated != 0 && info_.dof_actuated != 3 && info_.dof_actuated != 6) {
    return refuse(fmt::format("dof_actuated is {}, expected 0, 3 or 6", info_.dof_actuated));
  }
  // a device without a stated force limit cannot be protected by the safety stage
  if (info_.dof_actuated > 0 && !(info_.max_force_n > 0.0 && std::isfinite(info_.max_force_n))) {
    return refuse("reports no valid max_force_n; refusing to send it forces");
  }
  if (info_.dof_actuated == 6 && !(info_.max_torque_nm > 0.0 && std::isfinite(info_.max_torque_nm))) {
    return refuse("is 6-DOF actuated but reports no valid max_torque_nm; refusing to send it torques");
  }
  limiter_ = ForceLimiter(info_, options_.limits, options_.rate_hz);
  open_ = true;
  fade_count_ = 0;
  return Ok{};
}

const char* HapticManager::phase_name(TickPhase phase) {
  switch (phase) {
    case TickPhase::kReadState:
      return "reading the device state";
    case TickPhase::kMove:
      return "a MoveOnHapticTick delegate (moving the tool)";
    case TickPhase::kForce:
      return "a ForceOnHapticTick delegate (computing the force)";
    case TickPhase::kCommand:
      return "commanding the device";
    case TickPhase::kSent:
      return "a SentOnHapticTick delegate";
    case TickPhase::kIdle:
      break;
  }
  return "the haptic tick";
}

Status HapticManager::start() {
  if (!(options_.rate_hz > 0.0 && options_.rate_hz <= 10000.0)) {
    return Error{fmt::format("haptic manager: rate_hz {} is outside (0, 10000]", options_.rate_hz)};
  }
  if (running()) return Error{"haptic manager: already running"};
  if (Status s = open(); !s) return s;
  // a thread that ended by itself is joined by the loop's start(); its failure is history now
  failure_.clear();
  restart_fade_.store(true, std::memory_order_release);
  // from here the haptic thread reads the delegators: binding would race with it
  move_event_.refuse_binding(kMoveBindRefused);
  force_event_.refuse_binding(kForceBindRefused);
  sent_event_.refuse_binding(kSentBindRefused);
  auto on_tick = [this](const TickInfo& t) {
    const double now = std::chrono::duration<double>(t.start_time.time_since_epoch()).count();
    tick(now);
  };
  auto on_exit = [this](const LoopExit& exit) { on_loop_exit(exit); };
  Status started =
      servo_ != nullptr ? servo_->start(options_.rate_hz, on_tick, on_exit) : loop_.start(on_tick, on_exit);
  servo_run_started_ = servo_ != nullptr && started;
  if (!started) allow_binding();
  return started;
}

void HapticManager::on_loop_exit(const LoopExit& exit) {
  // haptic thread, the loop is over: zero first, everything else after; a driver whose
  // read_state() threw is not asked again
  send_final_zero(steady_now_s(), !(exit.callback_threw && phase_ == TickPhase::kReadState));
  if (exit.callback_threw && options_.fault_group != nullptr) options_.fault_group->trip();
  if (exit.callback_threw)
    failure_ = fmt::format("the haptic thread stopped: {} threw: {}; the device was sent zero force",
                           phase_name(phase_), exit.what);
}

void HapticManager::send_final_zero(double now_s, bool read_device) {
  const DeviceCommand zero{};
  device_->command(zero);
  limiter_.zero();
  ended_with_zero_ = true;
  TraceSample sample;
  sample.tick_time_s = now_s;
  // for the trace, the state after the zero, so that its device times keep increasing (it replays)
  sample.state = read_device && trace_ ? device_->read_state() : last_state_;
  sample.sent = zero;
  sample.flags = kTraceStopped;
  if (trace_ && !trace_->try_push(sample)) trace_dropped_.increment();
  sent_event_.broadcast(sample);
}

bool HapticManager::running() const { return servo_ != nullptr ? servo_->running() : loop_.running(); }

std::uint64_t HapticManager::missed_deadlines() const {
  return servo_ != nullptr ? servo_->missed_deadlines() : loop_.missed_deadlines();
}

void HapticManager::stop() {
  if (servo_ != nullptr && servo_run_started_) {
    servo_->stop();
    // a run whose last frame never came: the device's servo thread stopped answering (the clock
    // gave up on it and turned forces off, maybe before this stop); latched like any device fault
    if (!ended_with_zero_) latch_fault();
    servo_run_started_ = false;
  }
  loop_.stop();
  // the haptic thread is joined: this thread may talk to the device and bind delegates now
  allow_binding();
  // a threaded run ended with zero from the haptic thread itself; a stepped one ends here
  if (open_ && !ended_with_zero_) send_final_zero(tick_time_s_ + 1.0 / options_.rate_hz, true);
}

void HapticManager::allow_binding() {
  move_event_.allow_binding();
  force_event_.allow_binding();
  sent_event_.allow_binding();
}

Status HapticManager::thread_status() const {
  if (running() || failure_.empty()) return Ok{};
  return Error{failure_, ErrorKind::kThread};
}

Status HapticManager::device_status() {
  if (!faulted()) return Ok{};
  std::string why = device_->fault_reason();
  if (why.empty())
    why = fault_was_freeze_.load(std::memory_order_relaxed)
              ? fmt::format("its state stopped advancing for {} ticks", options_.max_frozen_ticks)
              : std::string("it reported an error without a reason");
  return Error{fmt::format("device '{}' faulted: {}; it was sent zero force", info_.name, why), ErrorKind::kDevice};
}

TraceSample HapticManager::step(double now_s) {
  assert(open_ && "uh::haptico::HapticManager::step(): open() the device first");
  assert(!running() && "uh::haptico::HapticManager::step(): a threaded session is running");
  return tick(now_s);
}

TraceSample HapticManager::tick(double now_s) {
  ticks_.increment();
  tick_time_s_ = now_s;
  ended_with_zero_ = false;
  TraceSample sample;
  sample.tick_time_s = now_s;
  phase_ = TickPhase::kReadState;
  sample.state = device_->read_state();
  last_state_ = sample.state;
  // a driver that keeps returning the same sample has stalled: its pose is no longer the hand's
  bool frozen = false;
  if (options_.max_frozen_ticks > 0 && sample.state.status == DeviceStatus::kOk) {
    if (has_device_time_ && !(sample.state.time_s > last_device_time_s_)) {
      frozen = ++frozen_ticks_ >= options_.max_frozen_ticks;
    } else {
      frozen_ticks_ = 0;
    }
    last_device_time_s_ = sample.state.time_s;
    has_device_time_ = true;
  }
  if (sample.state.status != DeviceStatus::kOk || frozen) {
    device_errors_.increment();
    if (!faulted_.load(std::memory_order_relaxed)) fault_was_freeze_.store(frozen, std::memory_order_relaxed);
    latch_fault();
    sample.flags |= kTraceDeviceError;
  } else {
    phase_ = TickPhase::kMove;
    move_event_.broadcast(sample.state);
    phase_ = TickPhase::kForce;
    force_event_.broadcast(sample.state, sample.requested);
  }

  DeviceCommand out = sample.requested;
  const bool nonfinite = !finite(out);
  if (nonfinite) sample.flags |= kTraceNonFinite;
  if (info_.dof_actuated < 6) out.torque = {};
  // the halt/fault state first: resume() and clear_fault() publish the fade restart before they
  // clear it, so a tick that sees it cleared also sees the restart
  const bool zero = halted_.load(std::memory_order_acquire) || faulted_.load(std::memory_order_acquire) ||
                    (options_.fault_group != nullptr && options_.fault_group->tripped());
  if (restart_fade_.exchange(false, std::memory_order_acq_rel)) fade_count_ = 0;
  if (zero || nonfinite) {
    // zero at once, past the rate limit: the chain ramps up from it afterwards
    if (zero) {
      sample.flags |= kTraceZeroed;
      fade_count_ = 0;
    }
    out = DeviceCommand{};
    limiter_.zero();
  } else {
    double gain = 1.0;
    if (static_cast<double>(fade_count_) < fade_ticks_) {
      // gain from the tick count, not a running sum, so that it reaches exactly 1
      ++fade_count_;
      gain = std::min(1.0, static_cast<double>(fade_count_) / fade_ticks_);
      if (gain < 1.0) sample.flags |= kTraceFading;
    }
    out = limiter_.apply(out, gain, sample.flags);
  }
  count(sample.flags);
  sample.sent = out;
  phase_ = TickPhase::kCommand;
  device_->command(out);

  if (trace_ && !trace_->try_push(sample)) trace_dropped_.increment();
  phase_ = TickPhase::kSent;
  sent_event_.broadcast(sample);
  phase_ = TickPhase::kIdle;
  return sample;
}

void HapticManager::latch_fault() {
  faulted_.store(true, std::memory_order_release);
  // the other devices of the group go to zero with this one
  if (options_.fault_group != nullptr) options_.fault_group->trip();
}

void HapticManager::count(std::uint32_t flags) {
  if ((flags & kTraceNonFinite) != 0) nonfinite_.increment();
  if ((flags & kTraceZeroed) != 0) zeroed_ticks_.increment();
  if ((flags & kTraceForceClamped) != 0) force_clamped_.increment();
  if ((flags & kTraceTorqueClamped) != 0) torque_clamped_.increment();
  if ((flags & kTraceDeviceLimit) != 0) device_limited_.increment();
  if ((flags & kTraceToolLimit) != 0) tool_limited_.increment();
  if ((flags & kTraceSafetyLimit) != 0) safety_limited_.increment();
  if ((flags & kTraceRateLimit) != 0) rate_limited_.increment();
}

std::size_t HapticManager::drain_trace(std::vector<TraceSample>& out) {
  if (!trace_) return 0;
  std::size_t n = 0;
  TraceSample s;
  while (trace_->try_pop(s)) {
    out.push_back(s);
    ++n;
  }
  return n;
}

std::size_t HapticManager::drain_trace(std::ostream& csv) {
  if (!trace_) return 0;
  std::size_t n = 0;
  TraceSample s;
  while (trace_->try_pop(s)) {
    write_trace_row(csv, s);
    ++n;
  }
  return n;
}

HapticStats HapticManager::stats() const {
  HapticStats s;
  s.loop = servo_ != nullptr ? servo_->stats() : loop_.stats();
  s.ticks = ticks_.load();
  s.force_clamped = force_clamped_.load();
  s.torque_clamped = torque_clamped_.load();
  s.limits = {.device = device_limited_.load(),
              .tool = tool_limited_.load(),
              .safety = safety_limited_.load(),
              .rate = rate_limited_.load()};
  s.nonfinite = nonfinite_.load();
  s.device_errors = device_errors_.load();
  s.zeroed_ticks = zeroed_ticks_.load();
  s.trace_dropped = trace_dropped_.load();
  s.faulted = faulted_.load(std::memory_order_acquire);
  s.halted = halted_.load(std::memory_order_acquire);
  return s;
}

}  // namespace uh::haptico
