// Sessions with two hardware devices at once, against the stand-in libraries: two devices of one
// library selected by serial, two drivers (one clocked by HD's scheduler, one by the manager's
// loop), and a fault of one device that zeroes the other.
#include <gtest/gtest.h>

#include <fmt/format.h>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "dhd_standin_control.hpp"
#include "hd_standin_control.hpp"
#include "scene_test_support.hpp"
#include "uh/controllers/haptic_session.hpp"

namespace uh::controllers {
namespace {

using testing::replaced;

struct MultiDeviceSessionTest : ::testing::Test {
  static void SetUpTestSuite() { cache_ = new std::filesystem::path(testing::fresh_cache("multi-device")); }
  static void TearDownTestSuite() {
    std::filesystem::remove_all(*cache_);
    delete cache_;
  }
  // the two-hands scene with each hand's device replaced: `left` and `right` are the device objects
  static std::unique_ptr<HapticSession> make(const std::string& left, const std::string& right) {
    std::string json = testing::two_hands_scene_json();
    const auto device_of = [&](const std::string& from_start) {
      const auto at = json.find(R"("device": { "driver": "sim-line",)" + std::string("\n                ") +
                                R"("config": { "start": )" + from_start);
      EXPECT_NE(at, std::string::npos);
      return at;
    };
    // each hand's device object runs to the end of its config: "} }"
    for (const auto& [start, replacement] :
         {std::pair{std::string("[0.0"), left}, std::pair{std::string("[0.15"), right}}) {
      const auto at = device_of(start);
      if (at == std::string::npos) return nullptr;
      const auto end = json.find("} }", at);
      json.replace(at, end + 3 - at, R"("device": )" + replacement);
    }
    auto scene = parse_scene(json, "hands.json", testing::test_assets());
    EXPECT_TRUE(scene) << scene.error().message;
    if (!scene) return nullptr;
    // The penalty path: each stand-in's handle rests inside its object (a spring holds it there),
    // and these tests are about the drivers carrying that contact's force; the proxy, by design,
    // leaves a handle that starts inside an object free until it comes out.
    SessionOptions options;
    options.cache_dir = *cache_;
    options.proxy = false;
    auto session = HapticSession::create(*scene, options);
    EXPECT_TRUE(session) << (session ? "" : session.error().message);
    return session ? std::move(session).value() : nullptr;
  }
  static std::string dhd(const std::string& selection) {
    return fmt::format(R"({{ "driver": "forcedimension", "config": {{ "library": "{}"{} }} }})",
                       devices::testing::DhdStandin::path(), selection);
  }
  static std::string hd() {
    return fmt::format(R"({{ "driver": "openhaptics", "config": {{ "library": "{}" }} }})",
                       devices::testing::HdStandin::path());
  }
  static std::filesystem::path* cache_;
};
std::filesystem::path* MultiDeviceSessionTest::cache_ = nullptr;

// two omega.3 of one library, picked by serial: each hand rests in its object and each device
// gets its own contact force, pushing it out
TEST_F(MultiDeviceSessionTest, TwoDevicesOfOneLibrarySelectedBySerial) {
  devices::testing::DhdStandin standin;
  standin.set("devices", 2);
  standin.set("rest_z", 0.05, 0);  // in the bunny
  standin.set("rest_x", 0.15, 1);  // in the ball
  standin.set("rest_z", 0.05, 1);
  auto session = make(dhd(R"(, "serial": 11001)"), dhd(R"(, "serial": 11002)"));
  ASSERT_TRUE(session);
  const Status ran = session->run_stepped(1.0, 1);
  ASSERT_TRUE(ran) << ran.error().message;
  const SessionReport& r = session->report();
  ASSERT_EQ(r.tools.size(), 2u);
  EXPECT_EQ(r.tools[0].device.serial, "11001");
  EXPECT_EQ(r.tools[1].device.serial, "11002");
  for (const ToolReport& t : r.tools) {
    EXPECT_GT(t.contact_ticks, 500u) << t.tool;
    EXPECT_GT(t.force_max_n, 0.5) << t.tool;
    EXPECT_EQ(t.force_nonfinite, 0u) << t.tool;
  }
  EXPECT_LE(r.tools[0].force_max_n, 6.0 + 1e-9);
  EXPECT_LE(r.tools[1].force_max_n, 4.0 + 1e-9) << "the right tool's own limit";
  EXPECT_GT(standin.get("z", 0), 0.05) << "each device pushed up out of its object";
  EXPECT_GT(standin.get("z", 1), 0.05);
  for (int d = 0; d < 2; ++d) {
    const auto received = standin.received(d);
    ASSERT_GT(received.size(), 500u);
    double largest = 0.0;
    for (const auto& f : received) largest = std::max(largest, std::hypot(f[0], f[1], f[2]));
    EXPECT_GT(largest, 0.5) << "device " << d;
    EXPECT_EQ(standin.get("force_z", d), 0.0) << "the end sent zero";
  }
}

// one device for two tools is refused, by index and by serial, naming it
TEST_F(MultiDeviceSessionTest, OneDeviceCannotServeTwoTools) {
  devices::testing::DhdStandin standin;
  standin.set("devices", 2);
  for (const auto& [by_serial, message] :
       {std::pair{false, std::string("device 0 is open already")},
        std::pair{true, std::string("the device with serial 11002 is open already")}}) {
    auto scene = parse_scene(testing::two_hands_scene_json(), "hands.json", testing::test_assets());
    ASSERT_TRUE(scene) << scene.error().message;
    for (auto* tool : {&scene->tools[0], &scene->tools[1]}) {
      tool->device.driver = "forcedimension";
      tool->device.config = {};
      tool->device.config.set("library", std::string(devices::testing::DhdStandin::path()));
    }
    if (by_serial) {
      scene->tools[0].device.config.set("serial", 11002.0);
      scene->tools[1].device.config.set("serial", 11002.0);
    }
    SessionOptions options;
    options.cache_dir = *cache_;
    auto session = HapticSession::create(*scene, options);
    ASSERT_FALSE(session);
    EXPECT_NE(session.error().message.find("hands.json: tools[1].device: forcedimension: " + message),
              std::string::npos)
        << session.error().message;
    EXPECT_EQ(session.error().kind, uh::ErrorKind::kBusy) << "the device is in use, kept through the session";
  }
  EXPECT_EQ(standin.get("open", 0), 0.0) << "everything opened was closed again";
  EXPECT_EQ(standin.get("open", 1), 0.0);
}

// the omega.3's bus fails mid-session (a stepped run: the devices tick in turn, the omega.3
// first): the simulated right hand's force is zero from the omega.3's faulted tick on, before the
// run's end sends zero, and the error names the faulted device
TEST_F(MultiDeviceSessionTest, AHardwareFaultZeroesTheOtherDevice) {
  devices::testing::DhdStandin standin;
  standin.set("rest_z", 0.05, 0);
  standin.set("comm_error_after", 300);
  auto session = make(dhd(""), R"({ "driver": "sim-line",
                           "config": { "start": [0.15, 0.0, 0.055], "end": [0.15, 0.0, 0.048], "duration_s": 0.5,
                                       "dof_actuated": 3, "max_force_n": 4 } })");
  ASSERT_TRUE(session);
  std::vector<double> right;  // |force| sent to the simulated device, per tick
  right.reserve(2000);
  auto seen = session->on_haptic_tick(1).connect(
      [&](const SessionState& s) { right.push_back(norm(s.force_world)); });
  const Status ran = session->run_stepped(1.0, 1);
  ASSERT_FALSE(ran);
  EXPECT_EQ(
      ran.error().message,
      "hands.json: tools[0] 'left': device 'forcedimension omega.3' faulted: sending the force "
      "(dhdSetForce): "
      "communication error (USB transfer failed); it was sent zero force; every device was sent zero force");
  EXPECT_EQ(standin.get("forces_enabled"), 0.0);
  EXPECT_EQ(standin.received().size(), 300u) << "nothing reached the omega.3 after the fault";
  // the right hand pressed into the ball until the fault; then zero, first in its own tick of the
  // faulted step (the run's end sends the last zero, one sample later)
  std::size_t first_zero = right.size();
  for (std::size_t i = 100; i < right.size(); ++i)
    if (right[i] == 0.0) {
      first_zero = i;
      break;
    }
  ASSERT_LT(first_zero + 1, right.size()) << "a zero before the run's end";
  EXPECT_GE(first_zero, 300u);
  EXPECT_LE(first_zero, 302u);
  EXPECT_GT(right[first_zero - 1], 0.1) << "in contact just before";
  for (std::size_t i = first_zero; i < right.size(); ++i) EXPECT_EQ(right[i], 0.0) << "tick " << i;
}

// HD's scheduler clocks the left hand, the manager's own loop the right: both render their
// contact at once within their limits; then HD's device fails and the other goes to zero with it
TEST_F(MultiDeviceSessionTest, OpenHapticsAndForceDimensionInOneThreadedSession) {
  devices::testing::HdStandin hd_standin;
  devices::testing::DhdStandin dhd_standin;
  hd_standin.set("rest_y", 0.05);  // HD's y is up: in the bunny
  dhd_standin.set("rest_x", 0.15, 0);
  dhd_standin.set("rest_z", 0.05, 0);
  {
    auto session = make(hd(), dhd(""));
    ASSERT_TRUE(session);
    const Status ran = session->run(0.4);
    ASSERT_TRUE(ran) << ran.error().message;
    const SessionReport& r = session->report();
    ASSERT_EQ(r.tools.size(), 2u);
    EXPECT_EQ(r.tools[0].device.name, "openhaptics Touch");
    EXPECT_EQ(r.tools[1].device.name, "forcedimension omega.3");
    for (const ToolReport& t : r.tools) {
      EXPECT_GT(t.haptic_ticks, 100u) << t.tool;
      EXPECT_GT(t.contact_ticks, 50u) << t.tool;
      EXPECT_GT(t.force_max_n, 0.5) << t.tool;
    }
    EXPECT_LE(r.tools[0].force_max_n, 3.3 + 1e-9) << "the Touch's own limit";
    EXPECT_LE(r.tools[1].force_max_n, 4.0 + 1e-9) << "the right tool's limit";
    EXPECT_EQ(hd_standin.get("force_output"), 0.0);
    EXPECT_EQ(dhd_standin.get("force_z"), 0.0) << "the end sent zero";
  }
  hd_standin.set("error_after_frames", 150);
  auto faulty = make(hd(), dhd(""));
  ASSERT_TRUE(faulty);
  const Status failed = faulty->run(30.0);
  ASSERT_FALSE(failed);
  EXPECT_NE(failed.error().message.find("tools[0] 'left': device 'openhaptics Touch' faulted"),
            std::string::npos)
      << failed.error().message;
  EXPECT_TRUE(faulty->report().stopped_early);
  EXPECT_GT(faulty->report().tools[1].zeroed_ticks, 0u);
  EXPECT_EQ(dhd_standin.get("force_z"), 0.0);
  const auto received = dhd_standin.received();
  ASSERT_FALSE(received.empty());
  EXPECT_EQ(std::hypot(received.back()[0], received.back()[1], received.back()[2]), 0.0);
  EXPECT_EQ(hd_standin.get("force_output"), 0.0);
}

}  // namespace
}  // namespace uh::controllers
