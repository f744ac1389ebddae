// Tests on a real device, run only when UH_HARDWARE names its driver (see docs/devices.md):
//   UH_HARDWARE=forcedimension ctest --test-dir build/release -L hardware --output-on-failure
// Hold the handle lightly: the forces are small (at most 1 N) and pull toward the workspace centre.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <string>
#include <thread>

#include "uh/devices/force_dimension_device.hpp"
#include "uh/devices/hardware_drivers.hpp"
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

#define UH_REQUIRE_HARDWARE(driver)                                                                          \
  if (!requested(driver)) GTEST_SKIP() << "set UH_HARDWARE=" driver " to run this test on a " driver " devi" \
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
  double last_time = -1.0;
  for (int i = 0; i < 2000; ++i) {
    const DeviceState s = device.read_state();
    ASSERT_EQ(s.status, DeviceStatus::kOk) << device.fault_reason();
    EXPECT_GT(s.time_s, last_time);
    last_time = s.time_s;
    // the handle is in (or near) the workspace the driver reports
    EXPECT_LE(std::abs(s.position.x), 2.0 * info.workspace_half_extents.x);
    EXPECT_LE(std::abs(s.position.y), 2.0 * info.workspace_half_extents.y);
    EXPECT_LE(std::abs(s.position.z), 2.0 * info.workspace_half_extents.z);
  }
  EXPECT_TRUE(device.close());
}

TEST(Hardware, ForceDimensionRendersAGentleSpringAndStopsAtZero) {
  UH_REQUIRE_HARDWARE("forcedimension");
  auto created = all_drivers().create("forcedimension", {{"max_force_n", "1"}});
  ASSERT_TRUE(created) << created.error().message;
  auto* fd = dynamic_cast<ForceDimensionDevice*>(created->get());
  haptico::HapticManager manager(std::move(created).value(), {.rate_hz = 1000.0});
  manager.force_on_haptic_tick().add_delegate([](const DeviceState& s, DeviceCommand& c) {
    c.force = -50.0 * s.position - 2.0 * s.linear_velocity;  // 50 N/m toward the centre, clamped to 1 N
  });
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
  EXPECT_GT(fd->com_rate_hz(), 500.0);
  std::printf("  DHD communication rate %.0f Hz, %llu ticks, %llu saturated\n", fd->com_rate_hz(),
              static_cast<unsigned long long>(manager.stats().ticks),
              static_cast<unsigned long long>(fd->saturated_commands()));
}

}  // namespace
}  // namespace uh::devices
