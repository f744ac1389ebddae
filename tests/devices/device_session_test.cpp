// Whole sessions (scene, collision, forces) on a hardware driver against its stand-in library.
#include <gtest/gtest.h>

#include <fmt/format.h>
#include <filesystem>
#include <string>

#include "dhd_standin_control.hpp"
#include "hd_standin_control.hpp"
#include "scene_test_support.hpp"
#include "uh/controllers/haptic_session.hpp"

namespace uh::controllers {
namespace {

using testing::replaced;

struct DeviceSessionTest : ::testing::Test {
  static void SetUpTestSuite() { cache_ = new std::filesystem::path(testing::fresh_cache("devices")); }
  static void TearDownTestSuite() {
    std::filesystem::remove_all(*cache_);
    delete cache_;
  }
  // the small scene with its tool bound to `driver` on the stand-in `library`
  static std::unique_ptr<HapticSession> make(const char* driver = "forcedimension",
                                             const char* library = devices::testing::DhdStandin::path()) {
    const std::string json = replaced(
        testing::small_scene_json(),
        R"("config": { "start": [0.0, 0.0, 0.10], "end": [0.0, 0.0, 0.045], "duration_s": 0.5, "bounce": true,
                            "dof_actuated": 6, "max_force_n": 6 })",
        fmt::format(R"("config": {{ "library": "{}" }})", library));
    auto scene =
        parse_scene(replaced(json, R"("driver": "sim-line")", fmt::format(R"("driver": "{}")", driver)),
                    "small.json", testing::test_assets());
    EXPECT_TRUE(scene) << scene.error().message;
    if (!scene) return nullptr;
    // The penalty path: the stand-in's handle rests inside an object (a spring holds it there), and
    // these tests are about the driver carrying that contact's force; the proxy, by design, leaves
    // a handle that starts inside an object free until it comes out.
    SessionOptions options;
    options.cache_dir = *cache_;
    options.proxy = false;
    auto session = HapticSession::create(*scene, options);
    EXPECT_TRUE(session) << (session ? "" : session.error().message);
    return session ? std::move(session).value() : nullptr;
  }
  static std::filesystem::path* cache_;
};
std::filesystem::path* DeviceSessionTest::cache_ = nullptr;

// the handle rests inside the bunny: the contact force pushes the spring out, within every limit
TEST_F(DeviceSessionTest, ForceDimensionSessionRendersTheContact) {
  devices::testing::DhdStandin standin;
  standin.set("rest_z", 0.045, 0);
  auto session = make();
  ASSERT_TRUE(session);
  const Status ran = session->run_stepped(1.0, 1);
  ASSERT_TRUE(ran) << ran.error().message;
  const SessionReport& r = session->report();
  EXPECT_GT(r.contact_ticks, 500u);
  EXPECT_GT(r.force_max_n, 0.5);
  EXPECT_LE(r.force_max_n, 6.0 + 1e-9);  // the tool's limit, below the omega.3's 12 N
  EXPECT_EQ(r.force_nonfinite, 0u);
  EXPECT_GT(standin.get("z"), 0.045);      // pushed up and out of the bunny
  EXPECT_EQ(standin.get("force_z"), 0.0);  // the run's end sent zero
}

// a communication error mid-session ends the run with an error naming the device and the
// vendor's message, the device stopped and at zero
TEST_F(DeviceSessionTest, ForceDimensionCommunicationErrorEndsTheSession) {
  devices::testing::DhdStandin standin;
  standin.set("rest_z", 0.045, 0);
  standin.set("comm_error_after", 300);
  auto session = make();
  ASSERT_TRUE(session);
  const Status ran = session->run_stepped(1.0, 1);
  ASSERT_FALSE(ran);
  EXPECT_EQ(
      ran.error().message,
      "small.json: device 'forcedimension omega.3' faulted: sending the force (dhdSetForce): communication "
      "error (USB transfer failed); it was sent zero force");
  EXPECT_TRUE(session->report().stopped_early);
  EXPECT_LT(session->report().haptic_ticks, 310u);
  EXPECT_EQ(standin.get("forces_enabled"), 0.0);
  EXPECT_EQ(standin.get("force_z"), 0.0);
}

// the same on the haptic thread: the run ends long before its time, with the error and zero force
TEST_F(DeviceSessionTest, ForceDimensionFaultEndsAThreadedRun) {
  devices::testing::DhdStandin standin;
  standin.set("rest_z", 0.045, 0);
  standin.set("comm_error_after", 300);
  auto session = make();
  ASSERT_TRUE(session);
  const Status ran = session->run(30.0);
  ASSERT_FALSE(ran);
  EXPECT_NE(
      ran.error().message.find("device 'forcedimension omega.3' faulted: sending the force (dhdSetForce): "
                               "communication error (USB transfer failed)"),
      std::string::npos)
      << ran.error().message;
  EXPECT_TRUE(session->report().stopped_early);
  EXPECT_EQ(standin.get("forces_enabled"), 0.0);
  EXPECT_EQ(standin.get("force_z"), 0.0);
  EXPECT_EQ(standin.received().size(), 300u);  // nothing reached the device after the fault
}

// the stylus rests inside the bunny (field z = HD's y): a threaded session clocked by HD's scheduler
// renders the contact within the Touch's 3.3 N, and a mid-session HD error ends it with HD's message
TEST_F(DeviceSessionTest, OpenHapticsSessionRendersTheContactOnHdsClock) {
  devices::testing::HdStandin standin;
  standin.set("rest_y", 0.045);
  auto session = make("openhaptics", devices::testing::HdStandin::path());
  ASSERT_TRUE(session);
  const Status ran = session->run(0.4);
  ASSERT_TRUE(ran) << ran.error().message;
  const SessionReport& r = session->report();
  EXPECT_GT(r.contact_ticks, 100u);
  EXPECT_GT(r.force_max_n, 0.5);
  EXPECT_LE(r.force_max_n, 3.3 + 1e-9);  // the Touch's nominal force, below the tool's 6 N
  EXPECT_GT(r.haptic_rate_hz, 0.0);      // the scheduler's frames
  EXPECT_GT(standin.get("y"), 0.045);    // pushed up and out of the bunny
  EXPECT_EQ(standin.get("force_y"), 0.0);
  EXPECT_EQ(standin.get("force_output"), 0.0);
  session.reset();  // releases the device: HD opens each device once

  standin.set("error_after_frames", 150);
  auto faulty = make("openhaptics", devices::testing::HdStandin::path());
  ASSERT_TRUE(faulty);
  const Status failed = faulty->run(30.0);
  ASSERT_FALSE(failed);
  EXPECT_NE(
      failed.error().message.find("device 'openhaptics Touch' faulted: the servo frame reported HD error "
                                  "0x302: Communication error"),
      std::string::npos)
      << failed.error().message;
  EXPECT_TRUE(faulty->report().stopped_early);
  EXPECT_EQ(standin.get("force_output"), 0.0);
}

}  // namespace
}  // namespace uh::controllers
