// Tests on a real device, run only when UH_HARDWARE names its driver (see docs/devices.md):
//   UH_HARDWARE=forcedimension (or openhaptics, haply) ctest --test-dir build/release -L hardware
//   --output-on-failure
// Hold the handle lightly: the forces are small (at most 1 N) and pull toward the workspace centre.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <string>
#include <thread>

#include "uh/devices/force_dimension_device.hpp"
#include "uh/devices/haply_device.hpp"
#include "uh/devices/hardware_drivers.hpp"
#include "uh/devices/open_haptics_device.hpp"
#include "uh/haptico/haptic_manager.hpp"

namespace uh::devices {
namespace {

using haptico::DeviceCommand;
using haptico::DeviceState;
using haptico::DeviceStatus;

bool requested(const std::string& driver) {
  const char* v = std::getenv("UH_HARDWARE");
  return v != nullptr && driver == v;
}

// `n` live states: each valid, time increasing, the handle in (or near) the reported workspace;
// closes the device
void expect_live_states(haptico::HapticDevice& device, int n) {
  const haptico::DeviceInfo info = device.info();
  double last_time = -1.0;
  for (int i = 0; i < n; ++i) {
    const DeviceState s = device.read_state();
    ASSERT_EQ(s.status, DeviceStatus::kOk) << device.fault_reason();
    EXPECT_GT(s.time_s, last_time);
    last_time = s.time_s;
    EXPECT_LE(std::abs(s.position.x), 2.0 * info.workspace_half_extents.x);
    EXPECT_LE(std::abs(s.position.y), 2.0 * info.workspace_half_extents.y);
    EXPECT_LE(std::abs(s.position.z), 2.0 * info.workspace_half_extents.z);
  }
  EXPECT_TRUE(device.close());
}

// 2000 ticks of a gentle spring toward the workspace centre (50 N/m, limited by the config's
// max_force_n), then stopped: it must end without a fault
void run_gentle_spring(haptico::HapticManager& manager) {
  manager.force_on_haptic_tick().add_delegate(
      [](const DeviceState& s, DeviceCommand& c) { c.force = -50.0 * s.position - 2.0 * s.linear_velocity; });
  const Status started = manager.start();
  ASSERT_TRUE(started) << started.error().message;
  // two seconds of ticks, however long they take
  while (manager.ticks() < 2000 && manager.running())
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  manager.stop();
  EXPECT_TRUE(manager.thread_status());
  const Status device = manager.device_status();
  EXPECT_TRUE(device) << device.error().message;
  EXPECT_GE(manager.stats().ticks, 2000u);
}

#define UH_REQUIRE_HARDWARE(driver)                                          \
  if (!requested(driver))                                                    \
  GTEST_SKIP() << "set UH_HARDWARE=" driver " to run this test on a " driver \
                  " devi"                                                    \
                  "ce"

TEST(Hardware, ForceDimensionDescribesItselfAndReadsLiveStates) {
  UH_REQUIRE_HARDWARE("forcedimension");
  auto created = all_drivers().create("forcedimension", {});
  ASSERT_TRUE(created) << created.error().message;
  auto& device = **created;
  const Status opened = device.open();
  ASSERT_TRUE(opened) << opened.error().message;
  const haptico::DeviceInfo info = device.info();
  std::printf("  %s, serial %u, max %.1f N\n", info.name.c_str(),
              dynamic_cast<ForceDimensionDevice&>(device).serial_number(), info.max_force_n);
  EXPECT_GT(info.max_force_n, 0.0);
  EXPECT_LE(info.max_force_n, 20.0);
  expect_live_states(device, 2000);
}

TEST(Hardware, ForceDimensionRendersAGentleSpringAndStopsAtZero) {
  UH_REQUIRE_HARDWARE("forcedimension");
  auto created = all_drivers().create("forcedimension", {{"max_force_n", "1"}});
  ASSERT_TRUE(created) << created.error().message;
  auto* fd = dynamic_cast<ForceDimensionDevice*>(created->get());
  haptico::HapticManager manager(std::move(created).value(), {.rate_hz = 1000.0});
  run_gentle_spring(manager);
  EXPECT_GT(fd->com_rate_hz(), 500.0);
  std::printf("  DHD communication rate %.0f Hz, %llu ticks, %llu saturated\n", fd->com_rate_hz(),
              static_cast<unsigned long long>(manager.stats().ticks),
              static_cast<unsigned long long>(fd->saturated_commands()));
}

TEST(Hardware, OpenHapticsDescribesItselfAndReadsLiveStates) {
  UH_REQUIRE_HARDWARE("openhaptics");
  auto created = all_drivers().create("openhaptics", {});
  ASSERT_TRUE(created) << created.error().message;
  auto& device = **created;
  const Status opened = device.open();
  ASSERT_TRUE(opened) << opened.error().message;
  const haptico::DeviceInfo info = device.info();
  std::printf("  %s, serial %s, max %.2f N\n", info.name.c_str(),
              dynamic_cast<OpenHapticsDevice&>(device).serial_number().c_str(), info.max_force_n);
  EXPECT_GT(info.max_force_n, 0.0);
  EXPECT_LE(info.max_force_n, 40.0);
  expect_live_states(device, 500);  // each read outside a run is one synchronous scheduler frame
}

TEST(Hardware, OpenHapticsRendersAGentleSpringOnHdsClock) {
  UH_REQUIRE_HARDWARE("openhaptics");
  auto created = all_drivers().create("openhaptics", {{"max_force_n", "0.8"}});
  ASSERT_TRUE(created) << created.error().message;
  haptico::HapticManager manager(std::move(created).value(), {.rate_hz = 1000.0});
  run_gentle_spring(manager);
  const haptico::HapticStats stats = manager.stats();
  EXPECT_GT(stats.loop.achieved_rate_hz, 500.0);
  std::printf("  HD scheduler %.0f Hz over %llu ticks, jitter p99 %.0f us\n", stats.loop.achieved_rate_hz,
              static_cast<unsigned long long>(stats.ticks), stats.loop.period_error.p99_ns * 1e-3);
}

// Haply: the Inverse Service running (Haply Hub) with the Inverse3 listed; UH_HAPLY_URL for another
// address. The service reports no workspace: the states are checked against 0.5 m, a bound no
// desk device exceeds, and printed so that the axes can be checked by moving the handle.
TEST(Hardware, HaplyDescribesItselfAndReadsLiveStates) {
  UH_REQUIRE_HARDWARE("haply");
  auto created = all_drivers().create("haply", {});
  ASSERT_TRUE(created) << created.error().message;
  auto& device = **created;
  const Status opened = device.open();
  ASSERT_TRUE(opened) << opened.error().message;
  const haptico::DeviceInfo info = device.info();
  std::printf("  %s at %s, %d-DOF sensed, the service lists %zu Inverse3\n", info.name.c_str(),
              dynamic_cast<HaplyDevice&>(device).url().path.c_str(), info.dof_sensed,
              dynamic_cast<HaplyDevice&>(device).inventory().size());
  double last_time = -1.0;
  for (int i = 0; i < 2000; ++i) {
    device.command({});  // outside a run each command is one exchange: a zero force, a fresh state
    const DeviceState s = device.read_state();
    ASSERT_EQ(s.status, DeviceStatus::kOk) << device.fault_reason();
    EXPECT_GT(s.time_s, last_time);
    last_time = s.time_s;
    EXPECT_LE(norm(s.position), 0.5);
    if (i % 250 == 0)
      std::printf("  position %+.4f %+.4f %+.4f m, buttons %u\n", s.position.x, s.position.y, s.position.z,
                  s.buttons);
  }
  EXPECT_TRUE(device.close());
}

TEST(Hardware, HaplyRendersAGentleSpringOnTheServicesClock) {
  UH_REQUIRE_HARDWARE("haply");
  auto created = all_drivers().create("haply", {{"max_force_n", "1"}});
  ASSERT_TRUE(created) << created.error().message;
  haptico::HapticManager manager(std::move(created).value(), {.rate_hz = 1000.0});
  ASSERT_TRUE(manager.open());
  // the service's origin is not the workspace's centre: the spring pulls toward where the handle was
  Vec3 anchor{};
  bool anchored = false;
  manager.move_on_haptic_tick().add_delegate([&](const DeviceState& s) {
    if (!anchored) anchor = s.position;
    anchored = true;
  });
  manager.force_on_haptic_tick().add_delegate([&](const DeviceState& s, DeviceCommand& c) {
    c.force = -50.0 * (s.position - anchor) - 2.0 * s.linear_velocity;
  });
  const Status started = manager.start();
  ASSERT_TRUE(started) << started.error().message;
  while (manager.ticks() < 2000 && manager.running())
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  manager.stop();
  const Status device = manager.device_status();
  EXPECT_TRUE(device) << device.error().message;
  const haptico::HapticStats stats = manager.stats();
  EXPECT_GE(stats.ticks, 2000u);
  std::printf("  the service's replies at %.0f Hz over %llu ticks, jitter p99 %.0f us\n",
              stats.loop.achieved_rate_hz, static_cast<unsigned long long>(stats.ticks),
              stats.loop.period_error.p99_ns * 1e-3);
}

}  // namespace
}  // namespace uh::devices
