// The openhaptics driver against the stand-in libHD, through the driver's real loading path. The
// stand-in runs its own scheduler thread, so every run here is clocked by the library.
#include "uh/devices/open_haptics_device.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <thread>

#include "hd_standin_control.hpp"
#include "uh/devices/hardware_drivers.hpp"
#include "uh/haptico/haptic_manager.hpp"

namespace uh::devices {
namespace {

using haptico::DeviceCommand;
using haptico::DeviceConfig;
using haptico::DeviceState;
using haptico::DeviceStatus;
using haptico::HapticManager;

DeviceConfig standin_config() { return DeviceConfig{{"library", testing::HdStandin::path()}}; }

std::unique_ptr<haptico::HapticDevice> make(const DeviceConfig& config) {
  return testing::make_device("openhaptics", config);
}

using testing::wait_for;

TEST(OpenHapticsDevice, IsRegisteredAndRejectsBadSettings) {
  const haptico::DeviceRegistry registry = all_drivers();
  EXPECT_TRUE(registry.contains("openhaptics"));
  auto typo = registry.create("openhaptics", {{"nmae", "Default Device"}});
  ASSERT_FALSE(typo);
  EXPECT_NE(typo.error().message.find("nmae"), std::string::npos) << typo.error().message;
  EXPECT_FALSE(registry.create("openhaptics", {{"max_force_n", "0"}}));
  EXPECT_FALSE(registry.create("openhaptics", {{"name", ""}}));
  auto stall = registry.create("openhaptics", {{"stall_limit_ms", "5"}});
  ASSERT_FALSE(stall);
  EXPECT_EQ(stall.error().message, "openhaptics: stall_limit_ms must be in [10, 10000]");
}

TEST(OpenHapticsDevice, AMissingLibraryListsEveryPlaceTried) {
  ::setenv("UH_OPENHAPTICS_LIBRARY", "/nonexistent/libHD.so", 1);
  auto device = make({});
  ASSERT_TRUE(device);
  const Status opened = device->open();
  ::unsetenv("UH_OPENHAPTICS_LIBRARY");
  ASSERT_FALSE(opened);
  const std::string& m = opened.error().message;
  EXPECT_EQ(m.rfind("openhaptics: could not load the OpenHaptics HD library; tried:", 0), 0u) << m;
  EXPECT_NE(m.find("/nonexistent/libHD.so (from UH_OPENHAPTICS_LIBRARY)"), std::string::npos) << m;
  EXPECT_NE(m.find("tool.device.config.library is not set"), std::string::npos) << m;
  // neither set: the vendor's names, each listed
  auto plain = make({});
  const Status vendor = plain->open();
  ASSERT_FALSE(vendor);  // no OpenHaptics on a build machine
  EXPECT_NE(vendor.error().message.find("libHD.so (from the vendor's install name)"), std::string::npos)
      << vendor.error().message;
  EXPECT_NE(vendor.error().message.find("UH_OPENHAPTICS_LIBRARY is not set"), std::string::npos);
}

// HD's frame (x right, y up, z toward the user, mm, origin at calibration) becomes the field's
// (x toward the operator, y right, z up, m, origin at the workspace centre)
TEST(OpenHapticsDevice, DescribesTheDeviceAndReadsInTheFieldsFrame) {
  testing::HdStandin standin;
  standin.set("workspace_min_y", -40.0);  // usable workspace y from -40 to 80 mm: centre y = 20 mm
  standin.set("workspace_max_y", 80.0);
  standin.set("rest_x", 0.010);  // [m] in HD's frame
  standin.set("rest_y", 0.050);
  standin.set("rest_z", 0.030);
  standin.set("rotation_y_rad", 0.3);
  standin.set("buttons", 2);
  auto device = make(standin_config());
  ASSERT_TRUE(device);
  const Status opened = device->open();
  ASSERT_TRUE(opened) << opened.error().message;
  const haptico::DeviceInfo info = device->info();
  EXPECT_EQ(info.name, "openhaptics Touch");
  EXPECT_EQ(info.dof_sensed, 6);
  EXPECT_EQ(info.dof_actuated, 3);
  EXPECT_DOUBLE_EQ(info.max_force_n, 3.3);
  EXPECT_DOUBLE_EQ(info.max_torque_nm, 0.0);
  // half extents: HD (80, 60, 35) mm -> field (z, x, y)
  EXPECT_NEAR(info.workspace_half_extents.x, 0.035, 1e-12);
  EXPECT_NEAR(info.workspace_half_extents.y, 0.080, 1e-12);
  EXPECT_NEAR(info.workspace_half_extents.z, 0.060, 1e-12);
  auto& oh = dynamic_cast<OpenHapticsDevice&>(*device);
  EXPECT_EQ(oh.serial_number(), "220-00042");
  EXPECT_EQ(standin.get("clamping"), 1.0);      // HD's own clamp on
  EXPECT_EQ(standin.get("force_output"), 0.0);  // forces stay off until a command asks for one

  // outside a run, a read is one synchronous frame of HD's scheduler
  const DeviceState s = device->read_state();
  ASSERT_EQ(s.status, DeviceStatus::kOk);
  // HD (10, 50 - 20, 30) mm -> field (30, 10, 30) mm
  EXPECT_NEAR(s.position.x, 0.030, 1e-9);
  EXPECT_NEAR(s.position.y, 0.010, 1e-9);
  EXPECT_NEAR(s.position.z, 0.030, 1e-9);
  // the stylus turned 0.3 rad about HD's y (up) is turned 0.3 rad about the field's z: HD's z axis
  // goes to (sin, 0, cos) in HD, which is (cos, sin, 0) in the field
  const Vec3 x_axis = rotate(s.orientation, Vec3{1.0, 0.0, 0.0});
  EXPECT_NEAR(x_axis.x, std::cos(0.3), 1e-9);
  EXPECT_NEAR(x_axis.y, std::sin(0.3), 1e-9);
  EXPECT_NEAR(x_axis.z, 0.0, 1e-9);
  const Vec3 z_axis = rotate(s.orientation, Vec3{0.0, 0.0, 1.0});
  EXPECT_NEAR(z_axis.z, 1.0, 1e-9);
  EXPECT_EQ(s.buttons, 2u);
  EXPECT_TRUE(device->close());
  EXPECT_EQ(standin.get("initialised"), 0.0);
  EXPECT_EQ(standin.get("scheduler_running"), 0.0);
}

// the haptic tick runs on HD's scheduler thread, once per frame, and its force reaches the device
// in HD's frame once the safety stage let it through
TEST(OpenHapticsDevice, TheSchedulerIsTheClockAndForcesArriveInHdsFrame) {
  testing::HdStandin standin;
  auto device = make(standin_config());
  ASSERT_TRUE(device);
  HapticManager manager(std::move(device), {.rate_hz = 1000.0, .soft_start_s = 0.05});
  std::atomic<int> elsewhere{0};
  std::atomic<int> ticks{0};
  manager.move_on_haptic_tick().add_delegate([&](const DeviceState&) {
    if (!standin.on_scheduler_thread()) elsewhere.fetch_add(1);
    ticks.fetch_add(1);
  });
  // 0.5 N toward the operator (field x) = HD's +z
  manager.force_on_haptic_tick().add_delegate([](const DeviceState&, DeviceCommand& c) {
    c.force = {0.5, 0.0, 0.0};
  });
  const Status started = manager.start();
  ASSERT_TRUE(started) << started.error().message;
  EXPECT_EQ(standin.get("rate_hz"), 1000.0);
  wait_for([&] { return manager.ticks() >= 300 || !manager.running(); });
  manager.stop();
  EXPECT_TRUE(manager.thread_status());
  EXPECT_TRUE(manager.device_status());
  EXPECT_GE(ticks.load(), 300);
  EXPECT_EQ(elsewhere.load(), 0);
  const haptico::HapticStats stats = manager.stats();
  EXPECT_EQ(stats.loop.ticks, stats.ticks + 1);  // the device's frames: every tick and the final zero's
  EXPECT_GT(stats.loop.achieved_rate_hz, 0.0);
  const auto received = standin.received();
  ASSERT_GE(received.size(), 250u);
  // forces came on with the first non-zero command: the fade-in's first step, 0.5 N / 50 ticks
  EXPECT_NEAR(received.front()[2], 0.01, 1e-9);
  EXPECT_NEAR(received.back()[2], 0.5, 1e-9);
  EXPECT_NEAR(received.back()[0], 0.0, 1e-12);
  EXPECT_NEAR(received.back()[1], 0.0, 1e-12);
  EXPECT_GT(standin.get("z"), 0.0);  // the spring gave way toward the user
  // the run ended with zero and the forces off
  EXPECT_EQ(standin.get("force_z"), 0.0);
  EXPECT_EQ(standin.get("force_output"), 0.0);
}

TEST(OpenHapticsDevice, SixDofDevicesGetTorquesInMilliNewtonMetres) {
  testing::HdStandin standin;
  standin.set("output_dof", 6);
  standin.set("max_torque_mnm", 188.0);
  auto device = make(standin_config());
  ASSERT_TRUE(device);
  ASSERT_TRUE(device->open());
  EXPECT_EQ(device->info().dof_actuated, 6);
  EXPECT_DOUBLE_EQ(device->info().max_torque_nm, 0.188);
  // 0.1 N m about the field's z (up) = HD's y; 0.3 N m asked about x is clamped with it to 0.188 N m
  device->command({.force = {0.0, 0.0, 0.2}, .torque = {0.0, 0.0, 0.1}});
  EXPECT_NEAR(standin.get("torque_y"), 100.0, 1e-9);
  EXPECT_NEAR(standin.get("force_y"), 0.2, 1e-12);
  device->command({.force = {}, .torque = {0.0, 0.0, 0.3}});
  EXPECT_NEAR(standin.get("torque_y"), 188.0, 1e-9);
  EXPECT_TRUE(device->close());
  EXPECT_EQ(standin.get("torque_y"), 0.0);
  EXPECT_EQ(standin.get("force_output"), 0.0);
}

TEST(OpenHapticsDevice, FailingToOpenNamesTheDeviceAndHdsMessage) {
  testing::HdStandin standin;
  standin.set("fail_open", 1);
  auto device = make(standin_config());
  ASSERT_TRUE(device);
  const Status opened = device->open();
  ASSERT_FALSE(opened);
  EXPECT_EQ(
      opened.error().message,
      "openhaptics: opening the default device (hdInitDevice) failed: HD error 0x302: Communication error");
  auto named = make({{"library", testing::HdStandin::path()}, {"name", "Left Touch"}});
  const Status by_name = named->open();
  ASSERT_FALSE(by_name);
  EXPECT_NE(by_name.error().message.find("opening 'Left Touch' (hdInitDevice)"), std::string::npos);
}

TEST(OpenHapticsDevice, RefusesADeviceWhoseCalibrationIsNotOk) {
  testing::HdStandin standin;
  standin.set("calibration", 0x5001);  // HD_CALIBRATION_NEEDS_UPDATE
  auto device = make(standin_config());
  ASSERT_TRUE(device);
  const Status opened = device->open();
  ASSERT_FALSE(opened);
  EXPECT_EQ(opened.error().message.rfind(
                "openhaptics: the calibration of the default device is not OK (hdCheckCalibration returned "
                "0x5001)",
                0),
            0u)
      << opened.error().message;
  EXPECT_EQ(standin.get("initialised"), 0.0);  // released again
  EXPECT_EQ(standin.get("force_output"), 0.0);
}

// an HD error mid-run: forces off at once, the manager latches the fault with HD's message, the
// device gets nothing more; a new open works
TEST(OpenHapticsDevice, AnErrorMidRunStopsTheForcesAndReopeningWorks) {
  testing::HdStandin standin;
  standin.set("error_after_frames", 200);
  auto device = make(standin_config());
  ASSERT_TRUE(device);
  {
    HapticManager manager(std::move(device), {.rate_hz = 1000.0});
    manager.force_on_haptic_tick().add_delegate([](const DeviceState&, DeviceCommand& c) {
      c.force = {0.0, 0.0, 1.0};
    });
    ASSERT_TRUE(manager.start());
    wait_for([&] { return manager.faulted(); });
    ASSERT_TRUE(manager.faulted());
    EXPECT_EQ(standin.get("force_output"), 0.0);
    const Status status = manager.device_status();
    ASSERT_FALSE(status);
    EXPECT_EQ(
        status.error().message,
        "device 'openhaptics Touch' faulted: the servo frame reported HD error 0x302: Communication error; "
        "it was sent zero force");
    manager.stop();
    EXPECT_LE(standin.received().size(), 200u);  // nothing reached the device after the fault
  }
  EXPECT_EQ(standin.get("initialised"), 0.0);  // the manager closed it
  standin.set("error_after_frames", -1);
  auto again = make(standin_config());
  HapticManager manager(std::move(again), {.rate_hz = 1000.0});
  ASSERT_TRUE(manager.start());
  wait_for([&] { return manager.ticks() >= 100; });
  manager.stop();
  EXPECT_TRUE(manager.device_status());
  EXPECT_EQ(standin.get("init_count"), 2.0);
}

// Starts `manager` pushing 1 N and waits until the stand-in's forces are on.
void start_pushing(HapticManager& manager, testing::HdStandin& standin) {
  manager.force_on_haptic_tick().add_delegate([](const DeviceState&, DeviceCommand& c) {
    c.force = {0.0, 0.0, 1.0};
  });
  ASSERT_TRUE(manager.start());
  wait_for([&] { return standin.get("force_output") == 1.0; });
  ASSERT_EQ(standin.get("force_output"), 1.0);
}

// a scheduler that stops running frames: stopping does not hang, turns the forces off without it
// and reports the device as faulted
TEST(OpenHapticsDevice, ASchedulerThatStopsAnsweringEndsWithForcesOffAndAFault) {
  testing::HdStandin standin;
  HapticManager manager(make(standin_config()), {.rate_hz = 1000.0});
  start_pushing(manager, standin);
  if (::testing::Test::HasFatalFailure()) return;
  standin.set("freeze", 1);
  manager.stop();  // gives up on the frozen scheduler after a bounded wait
  EXPECT_FALSE(manager.running());
  EXPECT_EQ(standin.get("force_output"), 0.0);
  const Status status = manager.device_status();
  ASSERT_FALSE(status);
  EXPECT_EQ(
      status.error().message,
      "device 'openhaptics Touch' faulted: the HD scheduler stopped running servo frames: no frame for 2 s; "
      "forces were disabled; it was sent zero force");
}

// a scheduler that stops running frames mid-run, with nobody stopping the run: the watchdog ends
// it at once, forces off, and the manager reports the device's fault when the session stops it
TEST(OpenHapticsDevice, AStallMidRunEndsTheRunAtOnceWithForcesOff) {
  testing::HdStandin standin;
  HapticManager manager(make(standin_config()), {.rate_hz = 1000.0});
  start_pushing(manager, standin);
  if (::testing::Test::HasFatalFailure()) return;
  standin.set("freeze", 1);
  wait_for([&] { return !manager.running(); });
  ASSERT_FALSE(manager.running()) << "the run ended by itself";
  EXPECT_EQ(standin.get("force_output"), 0.0);
  manager.stop();
  const Status status = manager.device_status();
  ASSERT_FALSE(status);
  EXPECT_EQ(
      status.error().message,
      "device 'openhaptics Touch' faulted: the HD scheduler stopped running servo frames: no frame for 250 "
      "ms; forces were disabled; it was sent zero force");
}

// The stall limit is the device's setting: a longer one rides out a longer stall, then ends the run
TEST(OpenHapticsDevice, TheStallLimitIsASetting) {
  testing::HdStandin standin;
  DeviceConfig config = standin_config();
  config.set("stall_limit_ms", 600.0);
  HapticManager manager(make(config), {.rate_hz = 1000.0});
  start_pushing(manager, standin);
  if (::testing::Test::HasFatalFailure()) return;
  standin.set("freeze", 1);
  const auto frozen = std::chrono::steady_clock::now();
  wait_for([&] { return !manager.running(); });
  ASSERT_FALSE(manager.running());
  EXPECT_GE(std::chrono::steady_clock::now() - frozen, std::chrono::milliseconds(600));
  EXPECT_EQ(standin.get("force_output"), 0.0);
  manager.stop();
  const Status status = manager.device_status();
  ASSERT_FALSE(status);
  EXPECT_NE(status.error().message.find("no frame for 600 ms"), std::string::npos) << status.error().message;
}

}  // namespace
}  // namespace uh::devices
