#include "uh/haptico/haptic_manager.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "allocation_counter.hpp"
#include "uh/core/log.hpp"
#include "uh/haptico/sim_hand_device.hpp"
#include "uh/haptico/sim_line_device.hpp"

namespace uh::haptico {
namespace {

// A scripted test double that logs every call, so tests can check the order of a tick.
class FakeDevice final : public HapticDevice {
 public:
  explicit FakeDevice(std::vector<std::string>* log) : log_(log) {
    info_.name = "fake";
    info_.dof_sensed = 6;
    info_.dof_actuated = 6;
    info_.max_force_n = 5.0;
    info_.max_torque_nm = 0.2;
  }
  DeviceInfo info() const override { return info_; }
  Status open() override {
    if (fail_open) return Error{"fake: no device on the bus"};
    return Ok{};
  }
  Status close() override {
    if (log_) log_->push_back("close");
    return Ok{};
  }
  DeviceState read_state() override {
    if (log_) log_->push_back("read");
    if (reads == throw_on_read) throw std::runtime_error("USB cable pulled");
    DeviceState s;
    s.time_s = frozen ? frozen_time : 0.001 * static_cast<double>(reads);
    ++reads;
    s.position = {0.01, 0.02, 0.03};
    s.status = status;
    return s;
  }
  void command(const DeviceCommand& cmd) override {
    if (log_) log_->push_back("command");
    last = cmd;
    last_command_thread = std::this_thread::get_id();
    ++commands;
  }
  std::string fault_reason() override {
    return status == DeviceStatus::kFault ? "fake: amplifier fault" : "";
  }

  DeviceInfo info_{};
  bool fail_open = false;
  bool frozen = false;  // keep returning the same timestamp
  double frozen_time = 0.0;
  DeviceStatus status = DeviceStatus::kOk;
  DeviceCommand last{};
  std::thread::id last_command_thread{};
  int throw_on_read = -1;  // read_state() throws on this read (0-based); -1: never
  int reads = 0;
  int commands = 0;

 private:
  std::vector<std::string>* log_;
};

// Waits until the haptic thread has run `ticks` ticks (or 10 s passed, which fails the caller's
// later checks): sleeping a fixed time would make the tests flaky on a loaded machine.
void wait_for_ticks(const HapticManager& manager, std::uint64_t ticks) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (manager.stats().ticks < ticks && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

// most tests check one stage of the tick: these options take the rate limit out of the way
constexpr ForceLimitOptions kNoRateLimit{
    .rate = {.max_force_n_per_s = kNoLimit, .max_torque_nm_per_s = kNoLimit}};

struct Fixture {
  std::vector<std::string> log;
  FakeDevice* device = nullptr;
  std::unique_ptr<HapticManager> manager;

  explicit Fixture(HapticManagerOptions options = {.soft_start_s = 0.0, .limits = kNoRateLimit},
                   bool with_log = true) {
    auto d = std::make_unique<FakeDevice>(with_log ? &log : nullptr);
    device = d.get();
    manager = std::make_unique<HapticManager>(std::move(d), options);
  }
};

TEST(HapticManager, StepRunsMoveThenForceThenCommand) {
  Fixture f;
  ASSERT_TRUE(f.manager->open());
  f.manager->move_on_haptic_tick().add_delegate([&](const DeviceState& s) {
    f.log.push_back("move");
    EXPECT_EQ(s.position, (Vec3{0.01, 0.02, 0.03}));
  });
  f.manager->force_on_haptic_tick().add_delegate([&](const DeviceState&, DeviceCommand& cmd) {
    f.log.push_back("force1");
    cmd.force += Vec3{1, 0, 0};
  });
  f.manager->force_on_haptic_tick().add_delegate([&](const DeviceState&, DeviceCommand& cmd) {
    f.log.push_back("force2");
    cmd.force += Vec3{0, 2, 0};
    cmd.torque += Vec3{0, 0, 0.1};
  });
  const TraceSample t = f.manager->step(3.5);
  EXPECT_EQ(f.log, (std::vector<std::string>{"read", "move", "force1", "force2", "command"}));
  EXPECT_EQ(f.device->last.force, (Vec3{1, 2, 0}));
  EXPECT_EQ(f.device->last.torque, (Vec3{0, 0, 0.1}));
  EXPECT_EQ(t.tick_time_s, 3.5);
  EXPECT_EQ(t.sent.force, (Vec3{1, 2, 0}));
  EXPECT_EQ(t.flags, 0u);
  EXPECT_EQ(f.manager->stats().ticks, 1u);
}

TEST(HapticManager, ClampsToDeviceLimitsKeepingDirection) {
  Fixture f;
  ASSERT_TRUE(f.manager->open());
  f.manager->force_on_haptic_tick().add_delegate([](const DeviceState&, DeviceCommand& cmd) {
    cmd.force = {30, 0, 40};
    cmd.torque = {0, 1, 0};
  });
  const TraceSample t = f.manager->step(0.0);
  EXPECT_NEAR(f.device->last.force.x, 3.0, 1e-12);
  EXPECT_NEAR(f.device->last.force.z, 4.0, 1e-12);
  EXPECT_NEAR(f.device->last.torque.y, 0.2, 1e-12);
  EXPECT_EQ(t.requested.force, (Vec3{30, 0, 40}));
  EXPECT_EQ(t.flags, kTraceForceClamped | kTraceTorqueClamped | kTraceDeviceLimit);
  EXPECT_EQ(f.manager->stats().force_clamped, 1u);
  EXPECT_EQ(f.manager->stats().torque_clamped, 1u);
  EXPECT_EQ(f.manager->stats().limits.device, 1u);
}

// The tool's and the safety limits join the device's (5 N, 0.2 N m): in every combination the
// force and torque sent are those of the smallest limit, and that limit is the one counted.
TEST(HapticManager, SmallestOfDeviceToolAndSafetyLimitWins) {
  struct Case {
    WrenchLimit tool, safety;
    double force, torque;  // expected |force|, |torque| sent
    std::uint32_t source;  // the limit credited
  };
  const Case cases[] = {
      {{}, {}, 5.0, 0.2, kTraceDeviceLimit},
      {{2.0, 0.1}, {}, 2.0, 0.1, kTraceToolLimit},
      {{}, {3.0, 0.15}, 3.0, 0.15, kTraceSafetyLimit},
      {{2.0, 0.1}, {3.0, 0.15}, 2.0, 0.1, kTraceToolLimit},
      {{3.0, 0.15}, {2.0, 0.1}, 2.0, 0.1, kTraceSafetyLimit},
      {{7.0, 0.3}, {6.0, 0.25}, 5.0, 0.2, kTraceDeviceLimit},
      {{5.0, 0.2}, {5.0, 0.2}, 5.0, 0.2, kTraceDeviceLimit},  // ties go to the device
      {{4.0, 0.1}, {4.0, 0.1}, 4.0, 0.1, kTraceToolLimit},    // then to the tool
  };
  for (const Case& c : cases) {
    Fixture f(
        {.soft_start_s = 0.0, .limits = {.tool = c.tool, .safety = c.safety, .rate = kNoRateLimit.rate}});
    ASSERT_TRUE(f.manager->open());
    f.manager->force_on_haptic_tick().add_delegate([](const DeviceState&, DeviceCommand& cmd) {
      cmd.force = {0, 30, 40};
      cmd.torque = {1, 0, 0};
    });
    const TraceSample t = f.manager->step(0.0);
    EXPECT_NEAR(norm(t.sent.force), c.force, 1e-12) << c.force;
    EXPECT_NEAR(t.sent.force.z / t.sent.force.y, 4.0 / 3.0, 1e-12) << "direction kept";
    EXPECT_NEAR(norm(t.sent.torque), c.torque, 1e-12) << c.torque;
    EXPECT_EQ(t.flags, kTraceForceClamped | kTraceTorqueClamped | c.source) << c.force;
    const LimitCounters n = f.manager->stats().limits;
    EXPECT_EQ(n.device, c.source == kTraceDeviceLimit ? 1u : 0u);
    EXPECT_EQ(n.tool, c.source == kTraceToolLimit ? 1u : 0u);
    EXPECT_EQ(n.safety, c.source == kTraceSafetyLimit ? 1u : 0u);
    EXPECT_EQ(n.rate, 0u);
  }
}

// A force that jumps (a late collision frame) reaches the device in steps of at most rate / tick
// rate; zero (halt) is sent at once, and the force ramps up again from it.
TEST(HapticManager, RateLimitBoundsEveryStepButNeverDelaysZero) {
  Fixture f({.rate_hz = 1000.0, .soft_start_s = 0.0, .limits = {.rate = {.max_force_n_per_s = 500.0}}});
  ASSERT_TRUE(f.manager->open());
  Vec3 wanted{};
  f.manager->force_on_haptic_tick().add_delegate(
      [&](const DeviceState&, DeviceCommand& cmd) { cmd.force = wanted; });
  wanted = {0, 0, 4.0};
  std::uint64_t limited = 0;
  for (int i = 1; i <= 8; ++i) {
    const TraceSample t = f.manager->step(0.001 * i);
    EXPECT_NEAR(t.sent.force.z, 0.5 * i, 1e-12) << "tick " << i;
    if ((t.flags & kTraceRateLimit) != 0) ++limited;
  }
  EXPECT_EQ(limited, 7u) << "the eighth step reaches 4 N exactly, within the limit";
  EXPECT_EQ(f.manager->step(0.009).sent.force.z, 4.0);
  f.manager->halt();
  EXPECT_EQ(f.manager->step(0.010).sent.force, Vec3{}) << "zero at once";
  f.manager->resume();
  EXPECT_NEAR(f.manager->step(0.011).sent.force.z, 0.5, 1e-12) << "from zero again";
  EXPECT_EQ(f.manager->stats().limits.rate, 8u);
}

TEST(HapticManager, NonFiniteCommandReplacedByZero) {
  Fixture f;
  ASSERT_TRUE(f.manager->open());
  f.manager->force_on_haptic_tick().add_delegate([](const DeviceState&, DeviceCommand& cmd) {
    cmd.force = {1, 0, 0};
    cmd.torque = {0, std::numeric_limits<double>::quiet_NaN(), 0};
  });
  f.manager->step(0.0);
  EXPECT_EQ(f.device->last.force, Vec3{});
  EXPECT_EQ(f.device->last.torque, Vec3{});
  EXPECT_EQ(f.manager->stats().nonfinite, 1u);
}

TEST(HapticManager, TorqueZeroedOnThreeDofDevice) {
  Fixture f;
  f.device->info_.dof_actuated = 3;
  f.device->info_.max_torque_nm = 0.0;
  ASSERT_TRUE(f.manager->open());
  f.manager->force_on_haptic_tick().add_delegate([](const DeviceState&, DeviceCommand& cmd) {
    cmd.force = {1, 0, 0};
    cmd.torque = {0, 0.1, 0};
  });
  f.manager->step(0.0);
  EXPECT_EQ(f.device->last.force, (Vec3{1, 0, 0}));
  EXPECT_EQ(f.device->last.torque, Vec3{});
  EXPECT_EQ(f.manager->stats().torque_clamped, 0u);
}

TEST(HapticManager, HaltZeroesUntilResume) {
  Fixture f;
  ASSERT_TRUE(f.manager->open());
  f.manager->force_on_haptic_tick().add_delegate([](const DeviceState&, DeviceCommand& cmd) { cmd.force = {1, 0, 0}; });
  f.manager->halt();
  EXPECT_EQ(f.manager->step(0.0).flags, kTraceZeroed);
  EXPECT_EQ(f.device->last.force, Vec3{});
  EXPECT_TRUE(f.manager->stats().halted);
  f.manager->resume();
  f.manager->step(0.001);
  EXPECT_EQ(f.device->last.force, (Vec3{1, 0, 0}));
  EXPECT_EQ(f.manager->stats().zeroed_ticks, 1u);
}

TEST(HapticManager, DeviceErrorLatchesZeroForce) {
  Fixture f;
  ASSERT_TRUE(f.manager->open());
  int force_calls = 0;
  f.manager->force_on_haptic_tick().add_delegate([&](const DeviceState&, DeviceCommand& cmd) {
    ++force_calls;
    cmd.force = {1, 0, 0};
  });
  f.device->status = DeviceStatus::kFault;
  const TraceSample t = f.manager->step(0.0);
  EXPECT_EQ(t.flags, kTraceDeviceError | kTraceZeroed);
  EXPECT_EQ(force_calls, 0);  // delegates never see an invalid state
  EXPECT_EQ(f.device->last.force, Vec3{});
  const Status fault = f.manager->device_status();
  ASSERT_FALSE(fault);
  EXPECT_EQ(fault.error().message, "device 'fake' faulted: fake: amplifier fault; it was sent zero force");
  // the device recovers, but the fault stays latched until someone clears it
  f.device->status = DeviceStatus::kOk;
  f.manager->step(0.001);
  EXPECT_EQ(f.device->last.force, Vec3{});
  EXPECT_TRUE(f.manager->stats().faulted);
  f.manager->clear_fault();
  f.manager->step(0.002);
  EXPECT_EQ(f.device->last.force, (Vec3{1, 0, 0}));
  EXPECT_EQ(f.manager->stats().device_errors, 1u);
}

// Two devices of one fault group, stepped: when one faults, the other sends zero from its next
// tick on (counted as zeroed, traced as such) although its own device is fine, and stays at zero.
// Deterministic counterpart of the threaded two-tool session test, whose timing decides how many
// ticks the other thread runs between the trip and the session's stop.
TEST(HapticManager, AFaultOfOneDeviceZeroesEveryDeviceOfItsGroup) {
  FaultGroup group;
  const HapticManagerOptions options{.soft_start_s = 0.0, .limits = kNoRateLimit, .fault_group = &group};
  Fixture left(options, false), right(options, false);
  ASSERT_TRUE(left.manager->open());
  ASSERT_TRUE(right.manager->open());
  for (Fixture* f : {&left, &right})
    f->manager->force_on_haptic_tick().add_delegate(
        [](const DeviceState&, DeviceCommand& cmd) { cmd.force = {0.0, 0.0, 2.0}; });
  left.manager->step(0.000);
  right.manager->step(0.000);
  EXPECT_EQ(left.device->last.force, (Vec3{0, 0, 2}));
  EXPECT_EQ(right.device->last.force, (Vec3{0, 0, 2}));
  EXPECT_FALSE(group.tripped());

  right.device->status = DeviceStatus::kFault;
  const TraceSample faulted = right.manager->step(0.001);
  EXPECT_EQ(faulted.flags, kTraceDeviceError | kTraceZeroed);
  EXPECT_TRUE(group.tripped());
  for (int i = 0; i < 3; ++i) {
    const TraceSample t = left.manager->step(0.001 + 0.001 * i);
    EXPECT_EQ(t.flags & kTraceZeroed, kTraceZeroed) << "tick " << i;
    EXPECT_EQ(t.sent.force, Vec3{});
    EXPECT_EQ(left.device->last.force, Vec3{});
  }
  EXPECT_EQ(left.manager->stats().zeroed_ticks, 3u);
  EXPECT_FALSE(left.manager->stats().faulted) << "the left device itself did not fault";
}

TEST(HapticManager, SoftStartFadesForceIn) {
  Fixture f({.rate_hz = 1000.0, .soft_start_s = 0.01});  // ten ticks
  ASSERT_TRUE(f.manager->open());
  f.manager->force_on_haptic_tick().add_delegate([](const DeviceState&, DeviceCommand& cmd) {
    cmd.force = {0, 0, 2};
    cmd.torque = {0.1, 0, 0};
  });
  for (int i = 1; i <= 10; ++i) {
    const TraceSample t = f.manager->step(0.001 * i);
    EXPECT_NEAR(t.sent.force.z, 0.2 * i, 1e-12) << "tick " << i;
    EXPECT_NEAR(t.sent.torque.x, 0.01 * i, 1e-12) << "tick " << i;
    EXPECT_EQ((t.flags & kTraceFading) != 0, i < 10);
  }
  EXPECT_EQ(f.manager->step(0.011).sent.force.z, 2.0);
  // after a halt the force fades in again instead of jumping back
  f.manager->halt();
  f.manager->step(0.012);
  f.manager->resume();
  EXPECT_NEAR(f.manager->step(0.013).sent.force.z, 0.2, 1e-12);
  for (int i = 0; i < 10; ++i) f.manager->step(0.014 + 0.001 * i);
  // and after a device fault is cleared
  f.device->status = DeviceStatus::kFault;
  f.manager->step(0.03);
  f.device->status = DeviceStatus::kOk;
  f.manager->clear_fault();
  EXPECT_NEAR(f.manager->step(0.031).sent.force.z, 0.2, 1e-12);
}

TEST(HapticManager, FrozenDeviceCountsAsDeviceError) {
  Fixture f({.soft_start_s = 0.0, .max_frozen_ticks = 3});
  ASSERT_TRUE(f.manager->open());
  f.manager->force_on_haptic_tick().add_delegate([](const DeviceState&, DeviceCommand& cmd) { cmd.force = {1, 0, 0}; });
  f.device->frozen = true;
  f.device->frozen_time = 0.0005;
  // the first sample and two repeats are tolerated (a device may be sampled faster than it updates)
  for (int i = 0; i < 3; ++i) EXPECT_EQ(f.manager->step(0.001 * i).sent.force, (Vec3{1, 0, 0})) << i;
  const TraceSample t = f.manager->step(0.003);
  EXPECT_EQ(t.flags, kTraceDeviceError | kTraceZeroed);
  EXPECT_EQ(f.device->last.force, Vec3{});
  EXPECT_EQ(f.manager->stats().device_errors, 1u);
  EXPECT_TRUE(f.manager->stats().faulted);
  ASSERT_FALSE(f.manager->device_status());
  EXPECT_EQ(f.manager->device_status().error().message,
            "device 'fake' faulted: its state stopped advancing for 3 ticks; it was sent zero force");
  EXPECT_EQ(f.manager->device_status().error().kind, uh::ErrorKind::kDevice);
  // a live device again, and the fault cleared: forces come back
  f.device->frozen = false;
  f.manager->clear_fault();
  EXPECT_TRUE(f.manager->device_status());
  EXPECT_EQ(f.manager->step(0.004).sent.force, (Vec3{1, 0, 0}));
}

TEST(HapticManager, OpenFailuresAreErrors) {
  Fixture f;
  f.device->fail_open = true;
  EXPECT_EQ(f.manager->open().error().message, "fake: no device on the bus");
  EXPECT_EQ(f.manager->start().error().message, "fake: no device on the bus");
  EXPECT_FALSE(f.manager->running());

  Fixture g;
  g.device->info_.max_force_n = std::numeric_limits<double>::infinity();
  EXPECT_EQ(g.manager->open().error().message,
            "device 'fake': reports no valid max_force_n; refusing to send it forces");
  EXPECT_FALSE(g.manager->is_open());

  Fixture h;
  h.device->info_.max_torque_nm = 0.0;
  EXPECT_FALSE(h.manager->open());

  Fixture bad_rate({.rate_hz = 0.0});
  EXPECT_EQ(bad_rate.manager->start().error().message, "haptic manager: rate_hz 0 is outside (0, 10000]");
}

TEST(HapticManager, TraceRecordsTicksAndWritesCsv) {
  Fixture f({.trace_capacity = 4, .soft_start_s = 0.0, .limits = kNoRateLimit});
  ASSERT_TRUE(f.manager->open());
  f.manager->force_on_haptic_tick().add_delegate([](const DeviceState&, DeviceCommand& cmd) { cmd.force = {0, 0, 2}; });
  // the queue may round its capacity up: overfill it by far and check that nothing is lost unseen
  const int ticks = 300;
  for (int i = 0; i < ticks; ++i) f.manager->step(0.001 * i);
  std::vector<TraceSample> samples;
  const std::size_t drained = f.manager->drain_trace(samples);
  EXPECT_GE(drained, 4u);
  EXPECT_GT(f.manager->stats().trace_dropped, 0u);
  EXPECT_EQ(drained + f.manager->stats().trace_dropped, static_cast<std::size_t>(ticks));
  EXPECT_EQ(samples[3].tick_time_s, 0.003);  // the oldest ticks are kept, later ones dropped
  EXPECT_EQ(samples[0].sent.force, (Vec3{0, 0, 2}));

  f.manager->step(0.5);
  std::ostringstream csv;
  write_trace_header(csv);
  EXPECT_EQ(f.manager->drain_trace(csv), 1u);
  const std::string text = csv.str();
  EXPECT_EQ(text.substr(0, 27), "tick_time_s,device_time_s,x");
  EXPECT_NE(text.find("\n0.5,0.3,0.01,0.02,0.03,1,0,0,0,"), std::string::npos) << text;
}

TEST(HapticManager, ThreadedRunTicksAndStopZeroesForce) {
  auto device = std::make_unique<SimLineDevice>(SimLineOptions{});
  SimLineDevice* raw = device.get();
  HapticManager manager(std::move(device), {.rate_hz = 1000.0, .soft_start_s = 0.0, .limits = kNoRateLimit});
  std::atomic<int> moves{0};
  std::atomic<int> forces{0};
  manager.move_on_haptic_tick().add_delegate([&](const DeviceState&) { moves.fetch_add(1); });
  manager.force_on_haptic_tick().add_delegate([&](const DeviceState&, DeviceCommand& cmd) {
    forces.fetch_add(1);
    cmd.force = {0, 0, 1.5};
  });
  ASSERT_TRUE(manager.start());
  EXPECT_TRUE(manager.running());
  wait_for_ticks(manager, 100);
  manager.stop();
  EXPECT_FALSE(manager.running());
  const HapticStats s = manager.stats();
  EXPECT_GE(s.ticks, 100u);
  EXPECT_EQ(s.ticks, static_cast<std::uint64_t>(forces.load()));
  EXPECT_EQ(moves.load(), forces.load());
  EXPECT_EQ(s.loop.ticks, s.ticks);
  // forces were rendered while running, and zero is what the device holds after stop()
  EXPECT_EQ(raw->commands(), s.ticks + 1);
  EXPECT_EQ(raw->last_command().force, Vec3{});
  // a stepped tick may follow a threaded session
  EXPECT_EQ(manager.step(1.0).sent.force, (Vec3{0, 0, 1.5}));
}

TEST(HapticManager, ThreadedRunAtFourKilohertz) {
  Fixture f({.rate_hz = 4000.0}, false);
  std::atomic<int> forces{0};
  f.manager->force_on_haptic_tick().add_delegate([&](const DeviceState&, DeviceCommand&) { forces.fetch_add(1); });
  ASSERT_TRUE(f.manager->start());
  EXPECT_FALSE(f.manager->start());  // already running
  wait_for_ticks(*f.manager, 400);
  f.manager->stop();
  EXPECT_GE(forces.load(), 400);
  EXPECT_EQ(f.manager->stats().loop.rate_hz, 4000.0);
  EXPECT_EQ(f.device->last.force, Vec3{});
}

TEST(HapticManager, TickTimeIsSteadyClockInThreadedSessions) {
  Fixture f({}, false);
  std::atomic<double> seen{0.0};
  f.manager->force_on_haptic_tick().add_delegate(
      [&](const DeviceState&, DeviceCommand&) { seen.store(f.manager->tick_time_s()); });
  const double before = std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  ASSERT_TRUE(f.manager->start());
  wait_for_ticks(*f.manager, 5);
  f.manager->stop();
  const double after = std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  EXPECT_GE(seen.load(), before);
  EXPECT_LE(seen.load(), after);
}

// Waits until the haptic thread has ended by itself (or 10 s passed).
void wait_for_end(const HapticManager& manager) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (manager.running() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

// A delegate that throws ends the haptic thread; before it exits, the thread itself commands zero
// (3 N were on the device), and the cause is kept. Nobody calls stop() before the checks.
TEST(HapticManager, ThrowingDelegateZeroesTheDeviceFromTheHapticThread) {
  Fixture f({.trace_capacity = 1024, .soft_start_s = 0.0, .limits = kNoRateLimit}, false);
  std::atomic<int> forces{0};
  f.manager->force_on_haptic_tick().add_delegate([&](const DeviceState&, DeviceCommand& cmd) {
    if (forces.fetch_add(1) == 50) throw std::runtime_error("contact solver diverged");
    cmd.force = {0, 0, 3.0};
  });
  ASSERT_TRUE(f.manager->start());
  wait_for_end(*f.manager);
  ASSERT_FALSE(f.manager->running()) << "the thread ended by itself";
  EXPECT_EQ(forces.load(), 51);
  EXPECT_EQ(f.device->last.force, Vec3{}) << "zero, before anyone called stop()";
  EXPECT_NE(f.device->last_command_thread, std::this_thread::get_id()) << "sent by the haptic thread";
  EXPECT_EQ(f.device->commands, 51) << "50 ticks with 3 N, then the zero";
  const Status status = f.manager->thread_status();
  ASSERT_FALSE(status.has_value());
  EXPECT_EQ(status.error().message,
            "the haptic thread stopped: a ForceOnHapticTick delegate (computing the force) threw: contact solver "
            "diverged; the device was sent zero force");
  EXPECT_EQ(status.error().kind, uh::ErrorKind::kThread);
  std::vector<TraceSample> trace;
  f.manager->drain_trace(trace);
  ASSERT_EQ(trace.size(), 51u);
  EXPECT_EQ(trace[49].sent.force.z, 3.0);
  EXPECT_EQ(trace.back().flags, kTraceStopped);
  EXPECT_EQ(trace.back().sent.force, Vec3{});
  f.manager->stop();
  EXPECT_EQ(f.device->commands, 51) << "the zero is sent once";
  EXPECT_FALSE(f.manager->thread_status().has_value()) << "the cause stays until the next start()";
  // the manager runs again after stop(); the new run has no failure
  ASSERT_TRUE(f.manager->start());
  EXPECT_TRUE(f.manager->thread_status().has_value());
  f.manager->stop();
}

TEST(HapticManager, ThrowingDriverIsNamedAndNotReadAgain) {
  Fixture f({.trace_capacity = 1024, .soft_start_s = 0.0, .limits = kNoRateLimit}, false);
  f.device->throw_on_read = 20;
  f.manager->force_on_haptic_tick().add_delegate([](const DeviceState&, DeviceCommand& cmd) { cmd.force = {1, 0, 0}; });
  ASSERT_TRUE(f.manager->start());
  wait_for_end(*f.manager);
  ASSERT_FALSE(f.manager->running());
  EXPECT_EQ(f.device->last.force, Vec3{});
  EXPECT_EQ(f.device->reads, 20) << "the stop sample does not ask a driver that threw";
  EXPECT_EQ(f.manager->thread_status().error().message,
            "the haptic thread stopped: reading the device state threw: USB cable pulled; the device was sent zero "
            "force");
  f.manager->stop();
}

// Stopped or stepped, a run ends with zero on the device and that zero as the trace's last sample.
TEST(HapticManager, StopOfASteppedRunSendsAndTracesZero) {
  Fixture f({.trace_capacity = 64, .soft_start_s = 0.0, .limits = kNoRateLimit}, false);
  ASSERT_TRUE(f.manager->open());
  f.manager->force_on_haptic_tick().add_delegate([](const DeviceState&, DeviceCommand& cmd) { cmd.force = {0, 2, 0}; });
  for (int i = 0; i < 5; ++i) f.manager->step(0.001 * i);
  EXPECT_EQ(f.device->last.force, (Vec3{0, 2, 0}));
  f.manager->stop();
  EXPECT_EQ(f.device->last.force, Vec3{});
  std::vector<TraceSample> trace;
  f.manager->drain_trace(trace);
  ASSERT_EQ(trace.size(), 6u);
  EXPECT_EQ(trace.back().flags, kTraceStopped);
  EXPECT_NEAR(trace.back().tick_time_s, 0.005, 1e-12);
  EXPECT_GT(trace.back().state.time_s, trace[4].state.time_s) << "device times keep increasing: the trace replays";
  f.manager->stop();
  EXPECT_EQ(f.device->commands, 6) << "stop() is idempotent";
  EXPECT_EQ(f.manager->drain_trace(trace), 0u);
}

// Binding while the haptic thread runs would race with it: refused, visibly, on every event.
TEST(HapticManager, BindingWhileRunningIsRefused) {
  Fixture f({}, false);
  f.manager->force_on_haptic_tick().add_delegate([](const DeviceState&, DeviceCommand& cmd) { cmd.force = {1, 0, 0}; });
  ASSERT_TRUE(f.manager->start());
  const std::uint64_t errors_before = log::message_count(log::Level::error);
  EXPECT_FALSE(f.manager->move_on_haptic_tick().add_delegate([](const DeviceState&) {}).valid());
  ScopedConnection force = f.manager->force_on_haptic_tick().connect([](const DeviceState&, DeviceCommand& cmd) {
    cmd.force = {100, 0, 0};
  });
  EXPECT_FALSE(force.connected());
  ScopedConnection sent = f.manager->sent_on_haptic_tick().connect([](const TraceSample&) {});
  EXPECT_FALSE(sent.connected());
  EXPECT_TRUE(f.manager->force_on_haptic_tick().binding_refused());
  EXPECT_EQ(f.manager->force_on_haptic_tick().size(), 1u);
  EXPECT_EQ(log::message_count(log::Level::error) - errors_before, 3u) << "each refusal says why";
  wait_for_ticks(*f.manager, 20);
  f.manager->stop();
  EXPECT_EQ(f.device->last.force, Vec3{});
  // stopped: binding works again
  EXPECT_FALSE(f.manager->force_on_haptic_tick().binding_refused());
  ScopedConnection later = f.manager->force_on_haptic_tick().connect([](const DeviceState&, DeviceCommand&) {});
  EXPECT_TRUE(later.connected());
}

TEST(HapticManager, TickDoesNotAllocate) {
  HapticManager manager(std::make_unique<SimHandDevice>(SimHandOptions{}), {.trace_capacity = 64});
  ASSERT_TRUE(manager.open());
  Vec3 seen{};
  manager.move_on_haptic_tick().add_delegate([&](const DeviceState& s) { seen = s.position; });
  manager.force_on_haptic_tick().add_delegate([](const DeviceState& s, DeviceCommand& cmd) {
    cmd.force += 500.0 * (Vec3{0, 0, -0.01} - s.position);
  });
  manager.step(0.0);  // warm-up outside the counted region
  uh::test::AllocationCounter counter;
  for (int i = 1; i <= 100; ++i) manager.step(0.001 * i);  // includes trace drops once the queue is full
  EXPECT_EQ(counter.count(), 0u);
  EXPECT_NE(seen, Vec3{});
}

TEST(HapticManager, DestructorSendsZeroAndCloses) {
  std::vector<std::string> log;
  auto d = std::make_unique<FakeDevice>(&log);
  {
    HapticManager manager(std::move(d));
    ASSERT_TRUE(manager.open());
  }
  ASSERT_GE(log.size(), 2u);
  EXPECT_EQ(log[log.size() - 2], "command");
  EXPECT_EQ(log.back(), "close");
}

}  // namespace
}  // namespace uh::haptico
