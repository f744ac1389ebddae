// The haply driver against the loopback stand-in of Haply's Inverse Service (a WebSocket server on
// an ephemeral port of 127.0.0.1, on its own thread), through the driver's real connection path.
#include "uh/devices/haply_device.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <thread>
#include <vector>

#include "standin_support.hpp"
#include "standins/haply_standin.hpp"
#include "uh/haptico/haptic_manager.hpp"

namespace uh::devices {
namespace {

using haptico::DeviceCommand;
using haptico::DeviceConfig;
using haptico::DeviceState;
using haptico::DeviceStatus;
using haptico::HapticManager;
using testing::HaplyFault;
using testing::HaplyStandinScript;
using testing::HaplyStandinService;

DeviceConfig config_for(const HaplyStandinService& service) { return DeviceConfig{{"url", service.url()}}; }

std::unique_ptr<haptico::HapticDevice> make(const DeviceConfig& config) {
  return testing::make_device("haply", config);
}

using testing::wait_for;

TEST(HaplyDevice, IsRegisteredAndRejectsBadSettings) {
  const haptico::DeviceRegistry registry = all_drivers();
  EXPECT_TRUE(registry.contains("haply"));
  auto typo = registry.create("haply", {{"devce_id", "049D"}});
  ASSERT_FALSE(typo);
  EXPECT_NE(typo.error().message.find("devce_id"), std::string::npos) << typo.error().message;
  auto scheme = registry.create("haply", {{"url", "http://127.0.0.1:10001"}});
  ASSERT_FALSE(scheme);
  EXPECT_EQ(
      scheme.error().message,
      "haply: url 'http://127.0.0.1:10001' (from tool.device.config.url): expected ws://HOST:PORT[/PATH]");
  EXPECT_FALSE(registry.create("haply", {{"url", "ws://127.0.0.1:port"}}));
  EXPECT_FALSE(registry.create("haply", {{"device_id", "04\"9D"}}));
  EXPECT_FALSE(registry.create("haply", {{"max_force_n", "0"}}));
  EXPECT_FALSE(registry.create("haply", {{"timeout_ms", "0"}}));
}

TEST(HaplyDevice, WithoutAServiceItSaysWhereItLooked) {
  std::string url;
  {
    HaplyStandinService gone;  // a port that was free a moment ago and has no listener now
    url = gone.url();
  }
  ::setenv("UH_HAPLY_URL", url.c_str(), 1);
  auto device = make({});
  ::unsetenv("UH_HAPLY_URL");
  ASSERT_TRUE(device);
  const Status opened = device->open();
  ASSERT_FALSE(opened);
  EXPECT_EQ(opened.error().message.rfind(
                fmt::format("haply: cannot reach the Inverse Service at {} (from UH_HAPLY_URL): ", url), 0),
            0u)
      << opened.error().message;
  EXPECT_NE(opened.error().message.find("is the service running?"), std::string::npos);
  EXPECT_EQ(device->read_state().status, DeviceStatus::kNotOpen);
  auto by_default = make({});
  EXPECT_EQ(static_cast<HaplyDevice&>(*by_default).url().path, "ws://127.0.0.1:10001");
  EXPECT_EQ(static_cast<HaplyDevice&>(*by_default).url().origin, "the service's default address");
}

TEST(HaplyDevice, DescribesOnlyWhatTheServiceReports) {
  HaplyStandinService service;
  auto device = make(config_for(service));
  ASSERT_TRUE(device);
  ASSERT_TRUE(device->open());
  const haptico::DeviceInfo info = device->info();
  EXPECT_EQ(info.name, "haply Inverse3 049D");
  EXPECT_EQ(info.model, "Inverse3");
  EXPECT_EQ(info.serial, "049D");
  EXPECT_EQ(info.dof_sensed, 3);  // no VerseGrip: no orientation
  EXPECT_EQ(info.dof_actuated, 3);
  EXPECT_EQ(info.max_force_n, HaplyDevice::kDefaultMaxForceN);
  EXPECT_EQ(info.max_torque_nm, 0.0);
  EXPECT_EQ(info.workspace_half_extents, Vec3{});  // the service reports none
  EXPECT_EQ(info.nominal_rate_hz, 0.0);
  ASSERT_TRUE(device->close());
  // opening sends nothing; closing sends a zero, whatever came before
  EXPECT_EQ(service.received(), std::vector<Vec3>{Vec3{}});

  auto wrong = make({{"url", service.url()}, {"device_id", "0FFF"}});
  const Status refused = wrong->open();
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().message,
            fmt::format("haply: the Inverse Service at {} (from tool.device.config.url): no Inverse3 with "
                        "device_id '0FFF' (the service reports: 049D)",
                        service.url()));
}

// positions in metres and forces in newtons, in the service's frame: nothing converted
TEST(HaplyDevice, UnitsAndFramesAreTheServicesOwn) {
  HaplyStandinScript script;
  script.start = {0.01, -0.02, 0.03};
  script.with_grip = true;
  script.grip_orientation = {0.5, 0.5, -0.5, 0.5};
  script.button_b = true;
  HaplyStandinService service(script);
  auto device = make({{"url", service.url()}, {"max_force_n", "3"}});
  ASSERT_TRUE(device->open());
  EXPECT_EQ(device->info().dof_sensed, 6);  // the grip brings the orientation
  DeviceState s = device->read_state();
  ASSERT_EQ(s.status, DeviceStatus::kOk);
  EXPECT_EQ(s.position, (Vec3{0.01, -0.02, 0.03}));
  EXPECT_EQ(s.orientation, (Quat{0.5, 0.5, -0.5, 0.5}));
  EXPECT_EQ(s.buttons, 2u);  // button b is bit 1

  // one exchange: the service gets the force as it is, and its mass takes one step under it
  const Vec3 f{0.5, -0.25, 1.0};
  device->command({.force = f});
  ASSERT_EQ(service.received().size(), 1u);
  EXPECT_EQ(service.received()[0], f);
  const DeviceState after = device->read_state();
  EXPECT_GT(after.time_s, s.time_s);
  // from rest, one semi-implicit Euler step of dt moves the 0.2 kg mass by F dt^2 / m
  const Vec3 step = f * (1e-6 / 0.2);
  EXPECT_NEAR(after.position.x, 0.01 + step.x, 1e-15);
  EXPECT_NEAR(after.position.y, -0.02 + step.y, 1e-15);
  EXPECT_NEAR(after.position.z, 0.03 + step.z, 1e-15);

  // under a constant force the spring settles at F / k (400 N/m): 1 mm for 0.4 N, along that axis
  for (int k = 0; k < 4000; ++k) device->command({.force = {0.0, 0.0, 0.4}});
  s = device->read_state();
  EXPECT_NEAR(s.position.z - 0.03, 0.4 / 400.0, 1e-6);
  EXPECT_NEAR(s.position.x, 0.01, 1e-6);
  EXPECT_NEAR(s.position.y, -0.02, 1e-6);

  // a force above the limit arrives at the limit, along its direction; a NaN arrives as zero
  device->command({.force = {0.0, 30.0, 40.0}});
  EXPECT_NEAR(service.received().back().y, 1.8, 1e-12);
  EXPECT_NEAR(service.received().back().z, 2.4, 1e-12);
  device->command({.force = {std::nan(""), 0.0, 0.0}});
  EXPECT_EQ(service.received().back(), Vec3{});
  ASSERT_TRUE(device->close());
  EXPECT_EQ(service.received().back(), Vec3{});
}

// the device is the clock: every tick runs on a reply, on the driver's network thread
TEST(HaplyDevice, EachReplyIsOneTickAndTheForcesAreThoseTheSafetyStageSent) {
  HaplyStandinScript script;
  script.start = {0.0, 0.0, 0.0};
  script.end = {0.0, 0.0, 0.02};
  script.motion_replies = 100;
  HaplyStandinService service(script);
  HapticManager manager(make(config_for(service)),
                        {.rate_hz = 1000.0, .trace_capacity = 4096, .soft_start_s = 0.05});
  std::vector<DeviceState> states;
  states.reserve(4096);
  std::thread::id tick_thread;
  std::atomic<int> other_threads{0};
  manager.move_on_haptic_tick().add_delegate([&](const DeviceState& s) {
    if (states.empty()) tick_thread = std::this_thread::get_id();
    if (std::this_thread::get_id() != tick_thread) other_threads.fetch_add(1);
    if (states.size() < states.capacity()) states.push_back(s);
  });
  manager.force_on_haptic_tick().add_delegate([](const DeviceState&, DeviceCommand& c) {
    c.force = {0.0, 0.0, 1.0};
  });
  ASSERT_TRUE(manager.start());
  wait_for([&] { return manager.ticks() >= 300 || !manager.running(); });
  manager.stop();
  ASSERT_TRUE(manager.device_status()) << manager.device_status().error().message;
  EXPECT_NE(tick_thread, std::this_thread::get_id());
  EXPECT_EQ(other_threads.load(), 0);
  const haptico::HapticStats stats = manager.stats();
  ASSERT_GE(stats.ticks, 300u);
  // one reply before each tick, and one for the final zero
  EXPECT_EQ(service.replies(), static_cast<std::int64_t>(stats.ticks) + 1);
  EXPECT_EQ(stats.loop.ticks, stats.ticks);
  // tick k saw reply k + 1 (the first reply answered the run's opening zero): the scripted path
  for (std::size_t k = 1; k < states.size(); ++k) ASSERT_GT(states[k].time_s, states[k - 1].time_s) << k;
  ASSERT_GE(states.size(), 50u);
  // the force pushes the mass too; early on (fading in) it has moved it by far less than 0.1 mm
  EXPECT_NEAR(states[9].position.z, service.scripted_position(10).z, 1e-4);

  std::vector<haptico::TraceSample> trace;
  manager.drain_trace(trace);
  const std::vector<Vec3> received = service.received();
  // the opening zero, each tick's force but the last one's, which the stop overtook: the final zero
  ASSERT_EQ(received.size(), trace.size());
  EXPECT_EQ(received.front(), Vec3{});
  for (std::size_t k = 0; k + 2 < trace.size(); ++k) ASSERT_EQ(received[k + 1], trace[k].sent.force) << k;
  EXPECT_EQ(trace.back().sent.force, Vec3{});
  // ramped in over 50 ticks, then the full newton; zero at the end
  EXPECT_NEAR(received[1].z, 1.0 / 50.0, 1e-12);
  EXPECT_NEAR(received[100].z, 1.0, 1e-12);
  EXPECT_EQ(received.back(), Vec3{});
}

struct FaultCase {
  HaplyFault fault;
  const char* message;  // what fault_reason() says
  bool zero_reaches_service;
};

void PrintTo(const FaultCase& c, std::ostream* out) { *out << c.message; }

class HaplyFaultTest : public ::testing::TestWithParam<FaultCase> {};

// each fault: the tick sees it at once, the device gets zero if the connection lives, the session
// learns the device and the service's message; re-opening afterwards works
TEST_P(HaplyFaultTest, EndsWithZeroForceAClearErrorAndReopens) {
  const FaultCase& fc = GetParam();
  HaplyStandinScript script;
  script.fault = fc.fault;
  script.fault_after = 200;
  HaplyStandinService service(script);
  auto device = make({{"url", service.url()}, {"timeout_ms", "30"}});
  HapticManager manager(std::move(device), {.rate_hz = 1000.0, .trace_capacity = 4096});
  manager.force_on_haptic_tick().add_delegate([](const DeviceState&, DeviceCommand& c) {
    c.force = {0.0, 0.0, 1.0};
  });
  ASSERT_TRUE(manager.start());
  wait_for([&] { return manager.faulted() && !manager.running(); });
  ASSERT_TRUE(manager.faulted());
  EXPECT_FALSE(manager.running()) << "the run ends by itself on a fault";
  const Status status = manager.device_status();
  ASSERT_FALSE(status);
  EXPECT_EQ(status.error().message,
            fmt::format("device 'haply Inverse3 049D' faulted: {}; it was sent zero force", fc.message));
  manager.stop();
  std::vector<haptico::TraceSample> trace;
  manager.drain_trace(trace);
  ASSERT_FALSE(trace.empty());
  EXPECT_EQ(trace.back().sent.force, Vec3{});
  // the last zero may still be on its way through the stand-in's thread
  const std::size_t expected = fc.zero_reaches_service ? 202u : 201u;
  wait_for([&] { return service.received().size() >= expected; });
  const std::vector<Vec3> received = service.received();
  ASSERT_GT(received.size(), 150u);
  EXPECT_NEAR(received[150].z, 1.0, 1e-12) << "forces were on before the fault";
  if (fc.zero_reaches_service) {
    EXPECT_EQ(received.back(), Vec3{});
    EXPECT_EQ(received.size(), 202u)
        << "the opening zero, 199 answered forces, the one that failed, the zero";
  } else {
    EXPECT_EQ(received.size(), 201u) << "nothing after the service dropped the connection";
  }

  // once the service works again, a device opens and runs on it again
  service.set_script({});
  HapticManager again(make(config_for(service)), {.rate_hz = 1000.0});
  const Status restarted = again.start();
  ASSERT_TRUE(restarted) << restarted.error().message;
  wait_for([&] { return again.ticks() >= 100; });
  again.stop();
  EXPECT_TRUE(again.device_status());
  EXPECT_EQ(service.connections(), 2);
  EXPECT_EQ(service.received().back(), Vec3{});
}

// outside a run each command is one exchange; a fault there too leaves the device faulted, and the
// same device object opens again
TEST(HaplyDevice, TheSameDeviceReopensAfterAFault) {
  HaplyStandinScript script;
  script.fault = HaplyFault::kError;
  script.fault_after = 5;
  HaplyStandinService service(script);
  auto device = make(config_for(service));
  ASSERT_TRUE(device->open());
  for (int k = 0; k < 5; ++k) device->command({.force = {0.1, 0.0, 0.0}});
  EXPECT_EQ(device->read_state().status, DeviceStatus::kOk);
  device->command({.force = {0.1, 0.0, 0.0}});
  EXPECT_EQ(device->read_state().status, DeviceStatus::kFault);
  EXPECT_EQ(device->fault_reason(), "the service reported an error: Inverse3 049D: the motors are too hot");
  EXPECT_EQ(service.received().back(), Vec3{}) << "the hang-up's zero";
  device->command({.force = {0.1, 0.0, 0.0}});  // nothing more goes out
  EXPECT_EQ(service.received().size(), 7u);
  ASSERT_TRUE(device->close());
  service.set_script({});
  ASSERT_TRUE(device->open());
  EXPECT_EQ(device->fault_reason(), "");
  device->command({.force = {0.1, 0.0, 0.0}});
  EXPECT_EQ(device->read_state().status, DeviceStatus::kOk);
  EXPECT_EQ(service.received().back(), (Vec3{0.1, 0.0, 0.0}));
  EXPECT_EQ(service.connections(), 2);
}

INSTANTIATE_TEST_SUITE_P(
    Faults, HaplyFaultTest,
    ::testing::Values(
        FaultCase{HaplyFault::kDrop, "the connection to the Inverse Service was lost: End of file", false},
        FaultCase{HaplyFault::kSilent,
                  "the Inverse Service did not answer within 30 ms: it stopped sending device states", true},
        FaultCase{HaplyFault::kError, "the service reported an error: Inverse3 049D: the motors are too hot",
                  true},
        FaultCase{HaplyFault::kBadJson,
                  "the service's reply is not a JSON object: {\"inverse3\": [{\"device_id\": \"049D\", \"sta",
                  true}),
    [](const ::testing::TestParamInfo<FaultCase>& p) {
      switch (p.param.fault) {
        case HaplyFault::kDrop:
          return std::string("Drop");
        case HaplyFault::kSilent:
          return std::string("Silent");
        case HaplyFault::kError:
          return std::string("Error");
        default:
          return std::string("BadJson");
      }
    });

}  // namespace
}  // namespace uh::devices
