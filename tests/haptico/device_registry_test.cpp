#include "uh/haptico/device_registry.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <string>

#include "uh/haptico/sim_line_device.hpp"

namespace uh::haptico {
namespace {

TEST(DeviceRegistry, UnknownNameListsKnownDrivers) {
  const DeviceRegistry registry = DeviceRegistry::with_simulated_devices();
  auto r = registry.create("phantom-omni");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().message,
            "unknown device driver 'phantom-omni' (known drivers: sim-circle, sim-hand, sim-line, sim-raster, sim-replay)");
  EXPECT_EQ(DeviceRegistry{}.create("x").error().message, "unknown device driver 'x' (known drivers: none)");
  EXPECT_EQ(r.error().kind, uh::ErrorKind::kDevice);
}

TEST(DeviceRegistry, CreatesEverySimulatedDriver) {
  const DeviceRegistry registry = DeviceRegistry::with_simulated_devices();
  for (const char* name : {"sim-line", "sim-circle", "sim-raster", "sim-hand"}) {
    auto r = registry.create(name);
    ASSERT_TRUE(r) << name << ": " << r.error().message;
    ASSERT_TRUE((*r)->open());
    EXPECT_EQ((*r)->info().name, name);
    EXPECT_EQ((*r)->read_state().status, DeviceStatus::kOk);
  }
}

TEST(DeviceRegistry, DriversCanBeAddedAndNotTwice) {
  DeviceRegistry registry;
  auto factory = [](const DeviceConfig& c) -> Result<std::unique_ptr<HapticDevice>> {
    auto duration = c.number("duration_s", 1.0);
    if (!duration) return duration.error();
    return std::unique_ptr<HapticDevice>(new SimLineDevice({.duration_s = *duration}));
  };
  ASSERT_TRUE(registry.register_driver("my-driver", factory));
  EXPECT_TRUE(registry.contains("my-driver"));
  EXPECT_EQ(registry.register_driver("my-driver", factory).error().message,
            "device registry: driver 'my-driver' is already registered");
  EXPECT_FALSE(registry.register_driver("", factory));
  EXPECT_FALSE(registry.register_driver("empty", nullptr));
  EXPECT_TRUE(registry.create("my-driver", {{"duration_s", "2"}}));
  EXPECT_EQ(registry.names(), std::vector<std::string>{"my-driver"});
}

TEST(DeviceRegistry, BadSettingsGiveErrorsNamingThem) {
  const DeviceRegistry registry = DeviceRegistry::with_simulated_devices();
  EXPECT_EQ(registry.create("sim-circle", {{"raduis", "0.1"}}).error().message,
            "sim-circle: unknown setting 'raduis' (known settings: rate_hz, max_force_n, max_torque_nm, dof_actuated, "
            "workspace, center, axis, radius, period_s)");
  EXPECT_EQ(registry.create("sim-line", {{"start", "0,0"}}).error().message,
            "sim-line: device setting 'start': '0,0' is not a vector \"x,y,z\" of three finite numbers");
  EXPECT_EQ(registry.create("sim-line", {{"duration_s", "fast"}}).error().message,
            "sim-line: device setting 'duration_s': 'fast' is not a finite number");
  EXPECT_EQ(registry.create("sim-line", {{"duration_s", "0"}}).error().message, "sim-line: duration_s must be positive");
  EXPECT_EQ(registry.create("sim-hand", {{"dof_actuated", "4"}}).error().message,
            "sim-hand: dof_actuated must be 3 or 6");
  EXPECT_EQ(registry.create("sim-raster", {{"lines", "2.5"}}).error().message,
            "sim-raster: lines must be a whole number in [1, 10000]");
  EXPECT_EQ(registry.create("sim-replay").error().message,
            "sim-replay: the setting 'file' (a CSV trajectory) is required");
  EXPECT_EQ(registry.create("sim-replay", {{"file", "/nonexistent/t.csv"}}).error().message,
            "sim-replay: /nonexistent/t.csv: cannot open the trajectory file (No such file or directory)");
}

TEST(DeviceRegistry, ConfigValuesReachTheDevice) {
  const DeviceRegistry registry = DeviceRegistry::with_simulated_devices();
  DeviceConfig config;
  config.set("start", Vec3{0.01, 0, 0}).set("end", Vec3{0.02, 0, 0}).set("max_force_n", 3.5).set("rate_hz", 4000.0);
  auto r = registry.create("sim-line", config);
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_TRUE((*r)->open());
  EXPECT_EQ((*r)->info().max_force_n, 3.5);
  EXPECT_EQ((*r)->info().nominal_rate_hz, 4000.0);
  EXPECT_NEAR((*r)->read_state().position.x, 0.01, 1e-15);
}

TEST(DeviceRegistry, ReplayDriverReadsFile) {
  const std::string path = testing::TempDir() + "uh_replay_registry_test.csv";
  {
    std::ofstream out(path);
    out << "time_s,x,y,z,qw,qx,qy,qz\n0,0.01,0,0,1,0,0,0\n1,0.02,0,0,1,0,0,0\n";
  }
  const DeviceRegistry registry = DeviceRegistry::with_simulated_devices();
  auto r = registry.create("sim-replay", {{"file", path}});
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_TRUE((*r)->open());
  EXPECT_NEAR((*r)->read_state().position.x, 0.01, 1e-15);
  std::remove(path.c_str());

  {
    std::ofstream out(path);
    out << "0,0.01,0,0,1,0,0,0\n0.5,0.01,0,0,1,0,0\n";
  }
  EXPECT_EQ(registry.create("sim-replay", {{"file", path}}).error().message,
            "sim-replay: " + path + ":2: found 7 fields, expected 8 (time_s,x,y,z,qw,qx,qy,qz)");
  std::remove(path.c_str());
}

}  // namespace
}  // namespace uh::haptico
