// The forcedimension driver against the stand-in libdhd, through the driver's real loading path.
#include "uh/devices/force_dimension_device.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <thread>
#include <vector>

#include "dhd_standin_control.hpp"
#include "uh/devices/hardware_drivers.hpp"
#include "uh/haptico/haptic_manager.hpp"

namespace uh::devices {
namespace {

using haptico::DeviceCommand;
using haptico::DeviceConfig;
using haptico::DeviceState;
using haptico::DeviceStatus;
using haptico::HapticManager;
using haptico::TraceSample;

DeviceConfig standin_config() { return DeviceConfig{{"library", testing::DhdStandin::path()}}; }

std::unique_ptr<haptico::HapticDevice> make(const DeviceConfig& config) {
  return testing::make_device("forcedimension", config);
}

TEST(ForceDimensionDevice, IsRegisteredAndRejectsBadSettings) {
  const haptico::DeviceRegistry registry = all_drivers();
  EXPECT_TRUE(registry.contains("forcedimension"));
  auto typo = registry.create("forcedimension", {{"seriall", "3"}});
  ASSERT_FALSE(typo);
  EXPECT_NE(typo.error().message.find("seriall"), std::string::npos) << typo.error().message;
  auto both = registry.create("forcedimension", {{"index", "0"}, {"serial", "3"}});
  ASSERT_FALSE(both);
  EXPECT_EQ(both.error().message, "forcedimension: give either index or serial, not both");
  EXPECT_FALSE(registry.create("forcedimension", {{"index", "1.5"}}));
  EXPECT_FALSE(registry.create("forcedimension", {{"max_force_n", "-1"}}));
}

TEST(ForceDimensionDevice, FindsTheLibraryThroughTheEnvironmentVariable) {
  testing::DhdStandin standin;
  ::setenv("UH_FORCEDIMENSION_LIBRARY", testing::DhdStandin::path(), 1);
  auto device = make({});
  ASSERT_TRUE(device);
  const Status opened = device->open();
  ::unsetenv("UH_FORCEDIMENSION_LIBRARY");
  ASSERT_TRUE(opened) << opened.error().message;
  auto* fd = dynamic_cast<ForceDimensionDevice*>(device.get());
  ASSERT_NE(fd, nullptr);
  EXPECT_EQ(fd->library_path(), testing::DhdStandin::path());
  EXPECT_TRUE(device->close());
}

TEST(ForceDimensionDevice, AMissingLibraryListsEveryPlaceTried) {
  ::unsetenv("UH_FORCEDIMENSION_LIBRARY");
  auto device = make({{"library", "/nonexistent/libdhd.so"}});
  ASSERT_TRUE(device);
  const Status opened = device->open();
  ASSERT_FALSE(opened);
  EXPECT_EQ(opened.error().message.rfind(
                "forcedimension: could not load the Force Dimension DHD library; tried:", 0),
            0u)
      << opened.error().message;
  EXPECT_NE(opened.error().message.find("/nonexistent/libdhd.so (from tool.device.config.library)"),
            std::string::npos);
  // without a config or an environment variable: the vendor's names, each listed
  auto plain = make({});
  const Status vendor = plain->open();
  ASSERT_FALSE(vendor);  // no Force Dimension SDK on a build machine
  EXPECT_NE(vendor.error().message.find("libdhd.so (from the vendor's install name)"), std::string::npos)
      << vendor.error().message;
  EXPECT_NE(vendor.error().message.find("UH_FORCEDIMENSION_LIBRARY is not set"), std::string::npos);
}

TEST(ForceDimensionDevice, DescribesTheModelFromItsRatedValues) {
  testing::DhdStandin standin;
  standin.set("system_type", 60, 0);  // a Falcon
  auto device = make(standin_config());
  ASSERT_TRUE(device->open());
  const haptico::DeviceInfo info = device->info();
  EXPECT_EQ(info.name, "forcedimension Falcon");
  EXPECT_EQ(info.dof_actuated, 3);
  EXPECT_EQ(info.max_force_n, 8.9);
  EXPECT_EQ(info.max_torque_nm, 0.0);
  EXPECT_EQ(dynamic_cast<ForceDimensionDevice&>(*device).serial_number(), 11001u);
  EXPECT_TRUE(device->close());
  // a lower limit is taken, a higher one refused: the driver never claims more than the device's rating
  auto lower = make({{"library", testing::DhdStandin::path()}, {"max_force_n", "3"}});
  ASSERT_TRUE(lower->open());
  EXPECT_EQ(lower->info().max_force_n, 3.0);
  EXPECT_TRUE(lower->close());
  auto higher = make({{"library", testing::DhdStandin::path()}, {"max_force_n", "12"}});
  const Status refused = higher->open();
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().message, "forcedimension: max_force_n 12 N is above the Falcon's rated 8.9 N");
  EXPECT_EQ(standin.get("open"), 0.0);  // closed again
  // a model the driver has no rating for must be given one
  standin.set("system_type", 999, 0);
  const Status unknown = make(standin_config())->open();
  ASSERT_FALSE(unknown);
  EXPECT_NE(unknown.error().message.find("prototype (system type 999) is not in the driver's table"),
            std::string::npos)
      << unknown.error().message;
  auto rated = make({{"library", testing::DhdStandin::path()}, {"max_force_n", "5"}});
  ASSERT_TRUE(rated->open());
  EXPECT_EQ(rated->info().max_force_n, 5.0);
}

TEST(ForceDimensionDevice, SelectsByIndexOrSerial) {
  testing::DhdStandin standin;
  standin.set("devices", 3);  // serials 11001, 11002, 11003
  standin.set("rest_x", 0.02, 2);
  auto by_serial = make({{"library", testing::DhdStandin::path()}, {"serial", "11003"}});
  ASSERT_TRUE(by_serial->open());
  EXPECT_EQ(dynamic_cast<ForceDimensionDevice&>(*by_serial).serial_number(), 11003u);
  EXPECT_DOUBLE_EQ(by_serial->read_state().position.x, 0.02);
  // the others were opened to read their serials, and closed again
  EXPECT_EQ(standin.get("open", 0), 0.0);
  EXPECT_EQ(standin.get("open", 1), 0.0);
  EXPECT_EQ(standin.get("open", 2), 1.0);
  EXPECT_TRUE(by_serial->close());
  auto by_index = make({{"library", testing::DhdStandin::path()}, {"index", "1"}});
  ASSERT_TRUE(by_index->open());
  EXPECT_EQ(dynamic_cast<ForceDimensionDevice&>(*by_index).serial_number(), 11002u);
  EXPECT_TRUE(by_index->close());
  const Status no_serial = make({{"library", testing::DhdStandin::path()}, {"serial", "7"}})->open();
  ASSERT_FALSE(no_serial);
  EXPECT_EQ(no_serial.error().message,
            "forcedimension: no device with serial 7 (found: serial 11001, serial 11002, serial 11003)");
  const Status no_index = make({{"library", testing::DhdStandin::path()}, {"index", "5"}})->open();
  ASSERT_FALSE(no_index);
  EXPECT_EQ(no_index.error().message, "forcedimension: index 5 asked for, but 3 devices are found");
}

TEST(ForceDimensionDevice, FailingToOpenGivesTheVendorsMessage) {
  testing::DhdStandin standin;
  standin.set("fail_open", 1);
  auto device = make(standin_config());
  const Status opened = device->open();
  ASSERT_FALSE(opened);
  EXPECT_EQ(opened.error().message,
            "forcedimension: opening device 0 failed: no device found (USB device not responding)");
  standin.set("devices", 0);
  const Status none = device->open();
  ASSERT_FALSE(none);
  EXPECT_NE(none.error().message.find("no device found by"), std::string::npos) << none.error().message;
}

// DHD's frame is the field's convention (x toward the operator, y right, z up) in metres and
// newtons: positions, orientations and forces pass through unchanged
TEST(ForceDimensionDevice, UnitsAndFramesPassThrough) {
  testing::DhdStandin standin;
  standin.set("rest_x", 0.01, 0);
  standin.set("rest_y", -0.02, 0);
  standin.set("rest_z", 0.03, 0);
  standin.set("rotation_z_rad", kPi / 2, 0);
  standin.set("buttons", 5, 0);
  auto device = make(standin_config());
  ASSERT_TRUE(device->open());
  const DeviceState s = device->read_state();
  EXPECT_EQ(s.status, DeviceStatus::kOk);
  EXPECT_EQ(s.position, (Vec3{0.01, -0.02, 0.03}));
  EXPECT_EQ(s.buttons, 5u);
  // a quarter turn about z: x goes to y
  const Vec3 x_turned = rotate(s.orientation, Vec3{1, 0, 0});
  EXPECT_NEAR(x_turned.x, 0.0, 1e-12);
  EXPECT_NEAR(x_turned.y, 1.0, 1e-12);
  EXPECT_NEAR(x_turned.z, 0.0, 1e-12);
  // forces are off until the first command, which turns them on and is delivered as given
  EXPECT_EQ(standin.get("forces_enabled"), 0.0);
  device->command({.force = {1.0, -2.0, 0.5}});
  EXPECT_EQ(standin.get("forces_enabled"), 1.0);
  ASSERT_EQ(standin.received().size(), 1u);
  EXPECT_EQ(standin.received()[0], (std::array<double, 3>{1.0, -2.0, 0.5}));
}

// the mechanism is a spring: a held force displaces it by F / k at rest (Hooke), read back in metres
TEST(ForceDimensionDevice, AHeldForceMovesTheHandleByForceOverStiffness) {
  testing::DhdStandin standin;
  standin.set("stiffness", 400.0, 0);
  auto device = make(standin_config());
  ASSERT_TRUE(device->open());
  DeviceState s;
  for (int i = 0; i < 3000; ++i) {
    s = device->read_state();
    device->command({.force = {2.0, 0.0, -1.0}});
  }
  EXPECT_NEAR(s.position.x, 2.0 / 400.0, 1e-6);
  EXPECT_NEAR(s.position.z, -1.0 / 400.0, 1e-6);
  EXPECT_NEAR(norm(s.linear_velocity), 0.0, 1e-6);
}

// every force the device receives is one the safety stage sent, in order, starting with the fade-in
TEST(ForceDimensionDevice, OnlyForcesFromTheSafetyStageReachTheDevice) {
  testing::DhdStandin standin;
  HapticManager manager(make(standin_config()),
                        {.rate_hz = 1000.0, .trace_capacity = 4096, .soft_start_s = 0.01});
  ASSERT_TRUE(manager.open());
  EXPECT_EQ(standin.get("forces_enabled"), 0.0);  // open() does not turn forces on
  manager.force_on_haptic_tick().add_delegate([](const DeviceState&, DeviceCommand& c) {
    c.force = {30.0, 0.0, 0.0};  // far above the omega.3's 12 N
  });
  for (int i = 0; i < 100; ++i) manager.step(0.001 * i);
  manager.stop();
  std::vector<TraceSample> trace;
  manager.drain_trace(trace);
  const auto received = standin.received();
  ASSERT_EQ(received.size(), trace.size());  // 100 ticks and the stop's zero
  for (std::size_t i = 0; i < trace.size(); ++i) {
    EXPECT_EQ(received[i][0], trace[i].sent.force.x) << i;
    EXPECT_LE(std::abs(received[i][0]), 12.0);
  }
  // ramped in: increasing, first step small, then held at the device's rated force, then zero
  EXPECT_GT(received[0][0], 0.0);
  EXPECT_LE(received[0][0], 1.0);
  for (std::size_t i = 1; i < 50; ++i) EXPECT_GE(received[i][0], received[i - 1][0]) << i;
  EXPECT_EQ(received[98][0], 12.0);
  EXPECT_EQ(received.back()[0], 0.0);
}

TEST(ForceDimensionDevice, TimeguardAndSaturationAreNotFaults) {
  testing::DhdStandin standin;
  standin.set("timeguard_every", 3);
  standin.set("saturation_n", 2.0, 0);
  auto owned = make(standin_config());
  auto& fd = dynamic_cast<ForceDimensionDevice&>(*owned);
  HapticManager manager(std::move(owned), {.soft_start_s = 0.0});
  ASSERT_TRUE(manager.open());
  manager.force_on_haptic_tick().add_delegate([](const DeviceState&, DeviceCommand& c) {
    c.force = {0.0, 5.0, 0.0};
  });
  for (int i = 0; i < 30; ++i) manager.step(0.001 * i);
  EXPECT_FALSE(manager.faulted());
  EXPECT_EQ(manager.stats().device_errors, 0u);
  EXPECT_EQ(fd.timeguard_reads(), 10u);
  // the first three ticks ramp up to 2 N at 1 N per tick; from the third the device clips 5 N to 2 N
  EXPECT_EQ(fd.saturated_commands(), 28u);
  EXPECT_EQ(standin.get("force_y"), 2.0);
}

// a communication error mid-session: forces off through dhdStop at once, zero from the manager,
// an error naming the device and the vendor's message; the device opens again afterwards
TEST(ForceDimensionDevice, ACommunicationErrorStopsTheDeviceAndReopens) {
  testing::DhdStandin standin;
  standin.set("comm_error_after", 20);
  HapticManager manager(make(standin_config()), {.soft_start_s = 0.0});
  ASSERT_TRUE(manager.open());
  manager.force_on_haptic_tick().add_delegate([](const DeviceState&, DeviceCommand& c) {
    c.force = {0.0, 0.0, 1.0};
  });
  for (int i = 0; i < 25; ++i) manager.step(0.001 * i);
  EXPECT_TRUE(manager.faulted());
  EXPECT_EQ(standin.get("forces_enabled"), 0.0);
  EXPECT_EQ(standin.get("stop_calls"), 1.0);
  EXPECT_EQ(standin.get("force_z"), 0.0);
  EXPECT_EQ(standin.received().size(), 20u);
  const Status status = manager.device_status();
  ASSERT_FALSE(status);
  EXPECT_EQ(
      status.error().message,
      "device 'forcedimension omega.3' faulted: sending the force (dhdSetForce): communication error (USB "
      "transfer failed); it was sent zero force");
  // later ticks send nothing: the stopped device stays stopped
  const std::size_t received = standin.received().size();
  manager.step(0.03);
  EXPECT_EQ(standin.received().size(), received);
  EXPECT_EQ(manager.stats().device_errors, 5u);
}

// a fault while reading: the same handling, named after the read; the device opens again
TEST(ForceDimensionDevice, AReadErrorStopsTheDeviceWhichOpensAgain) {
  testing::DhdStandin standin;
  auto device = make(standin_config());
  ASSERT_TRUE(device->open());
  device->command({.force = {1.0, 0.0, 0.0}});
  EXPECT_EQ(standin.get("force_x"), 1.0);
  standin.set("break_now", 1);
  EXPECT_EQ(device->read_state().status, DeviceStatus::kFault);
  EXPECT_EQ(standin.get("forces_enabled"), 0.0);
  EXPECT_EQ(standin.get("force_x"), 0.0);
  EXPECT_EQ(
      device->fault_reason(),
      "reading the position (dhdGetPositionAndOrientationFrame): communication error (USB transfer failed)");
  EXPECT_EQ(device->read_state().status, DeviceStatus::kFault);
  device->command({.force = {1.0, 0.0, 0.0}});
  EXPECT_EQ(standin.get("force_x"), 0.0);  // a stopped device stays stopped

  // the cable is back: close, open again, and it works
  EXPECT_TRUE(device->close());
  EXPECT_EQ(standin.get("open"), 0.0);
  ASSERT_TRUE(device->open());
  EXPECT_EQ(device->fault_reason(), "");
  EXPECT_EQ(device->read_state().status, DeviceStatus::kOk);
  device->command({.force = {1.0, 0.0, 0.0}});
  EXPECT_EQ(standin.get("force_x"), 1.0);
  EXPECT_TRUE(device->close());
  EXPECT_EQ(standin.get("force_x"), 0.0);
  EXPECT_EQ(standin.get("stop_calls"), 3.0);  // the fault and both closes
}

// the threaded loop: forces reach the device from the haptic thread, and stop() leaves it at zero
TEST(ForceDimensionDevice, AThreadedSessionEndsAtZero) {
  testing::DhdStandin standin;
  auto owned = make(standin_config());
  auto& fd = dynamic_cast<ForceDimensionDevice&>(*owned);
  HapticManager manager(std::move(owned), {.rate_hz = 1000.0});
  manager.force_on_haptic_tick().add_delegate([](const DeviceState&, DeviceCommand& c) {
    c.force = {0.0, 1.0, 0.0};
  });
  ASSERT_TRUE(manager.start());
  while (manager.ticks() < 1100)  // the communication rate is sampled every 1024 reads
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_EQ(standin.get("force_y"), 1.0);
  manager.stop();
  EXPECT_EQ(standin.get("force_y"), 0.0);
  EXPECT_FALSE(manager.faulted());
  EXPECT_GT(fd.com_rate_hz(), 0.0);
}

}  // namespace
}  // namespace uh::devices
