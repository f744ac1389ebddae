// Sessions with several tools, each on its own device: forces per tool, checked against each tool
// run alone; a fault of one device zeroes every device.
#include <gtest/gtest.h>

#include <atomic>
#include <string>
#include <vector>

#include "forwarding_device.hpp"
#include "scene_test_support.hpp"
#include "uh/controllers/haptic_session.hpp"

namespace uh::controllers {
namespace {

using testing::test_assets;
using testing::two_hands_scene_json;

// A sim-line device that faults (kFault, with a reason) from its `fault_after`-th read on, and
// records every force it was commanded: the test's view of what reached the hand.
class FaultingDevice : public testing::ForwardingDevice {
 public:
  FaultingDevice(std::unique_ptr<haptico::HapticDevice> inner, std::int64_t fault_after,
                 std::vector<Vec3>* commanded)
      : ForwardingDevice(std::move(inner)), fault_after_(fault_after), commanded_(commanded) {}
  haptico::DeviceState read_state() override {
    haptico::DeviceState s = inner().read_state();
    if (fault_after_ >= 0 && ++reads_ > fault_after_) s.status = haptico::DeviceStatus::kFault;
    return s;
  }
  void command(const haptico::DeviceCommand& cmd) override {
    if (commanded_->size() < commanded_->capacity()) commanded_->push_back(cmd.force);
    inner().command(cmd);
  }
  std::string fault_reason() override {
    return reads_ > fault_after_ && fault_after_ >= 0 ? "cable pulled" : "";
  }

 private:
  std::int64_t fault_after_;
  std::int64_t reads_ = 0;
  std::vector<Vec3>* commanded_;
};

struct MultiToolFixture : ::testing::Test {
  static void SetUpTestSuite() { cache_ = new std::filesystem::path(testing::fresh_cache("multi-tool")); }
  static void TearDownTestSuite() {
    std::filesystem::remove_all(*cache_);
    delete cache_;
  }
  static std::unique_ptr<HapticSession> make(
      const std::string& json, const haptico::DeviceRegistry& registry = devices::all_drivers()) {
    auto scene = parse_scene(json, "hands.json", test_assets());
    EXPECT_TRUE(scene.has_value()) << scene.error().message;
    if (!scene) return nullptr;
    SessionOptions options;
    options.cache_dir = *cache_;
    auto session = HapticSession::create(*scene, options, registry);
    EXPECT_TRUE(session.has_value()) << session.error().message;
    return session ? std::move(session).value() : nullptr;
  }
  // every published force of tool `tool` of a stepped run (world frame) [N]
  static std::vector<Vec3> stepped_forces(HapticSession& session, std::size_t tool, double seconds,
                                          std::vector<Vec3>* other = nullptr) {
    std::vector<Vec3> forces;
    std::vector<Vec3> other_forces;
    auto seen = session.on_haptic_tick(tool).connect([&](const SessionState& s) {
      EXPECT_EQ(s.tool, static_cast<std::int32_t>(tool));
      forces.push_back(s.force_world);
    });
    ScopedConnection seen_other;
    if (other != nullptr)
      seen_other = session.on_haptic_tick(1 - tool).connect(
          [&](const SessionState& s) { other->push_back(s.force_world); });
    const Status ran = session.run_stepped(seconds, 4);
    EXPECT_TRUE(ran) << ran.error().message;
    return forces;
  }
  static std::filesystem::path* cache_;
};
std::filesystem::path* MultiToolFixture::cache_ = nullptr;

// Each tool touches its own object: its forces are those of a session in which it is alone (the
// reference: the same scene with that one tool), tick by tick, and both hands feel contact.
TEST_F(MultiToolFixture, EachToolFeelsWhatItWouldFeelAlone) {
  auto both = make(two_hands_scene_json("both"));
  ASSERT_TRUE(both);
  ASSERT_EQ(both->tool_count(), 2u);
  std::vector<Vec3> right_in_both;
  const std::vector<Vec3> left_in_both = stepped_forces(*both, 0, 1.0, &right_in_both);
  const SessionReport& r = both->report();

  auto left = make(two_hands_scene_json("left"));
  auto right = make(two_hands_scene_json("right"));
  ASSERT_TRUE(left && right);
  const std::vector<Vec3> left_alone = stepped_forces(*left, 0, 1.0);
  const std::vector<Vec3> right_alone = stepped_forces(*right, 0, 1.0);

  ASSERT_EQ(left_in_both.size(), left_alone.size());
  ASSERT_EQ(right_in_both.size(), right_alone.size());
  double left_max = 0.0, right_max = 0.0;
  for (std::size_t i = 0; i < left_alone.size(); ++i) {
    EXPECT_LE(norm(left_in_both[i] - left_alone[i]), 1e-9) << "left, tick " << i;
    EXPECT_LE(norm(right_in_both[i] - right_alone[i]), 1e-9) << "right, tick " << i;
    left_max = std::max(left_max, norm(left_alone[i]));
    right_max = std::max(right_max, norm(right_alone[i]));
  }
  EXPECT_GT(left_max, 0.5) << "the left stylus presses into the bunny";
  EXPECT_GT(right_max, 0.5) << "the right stylus presses into the ball";
  EXPECT_LE(right_max, 4.0 + 1e-9) << "the right tool's own limit";

  // the report: per tool, the first also at the top level; each tool's limits its own
  ASSERT_EQ(r.tools.size(), 2u);
  EXPECT_EQ(r.tools[0].tool, "left");
  EXPECT_EQ(r.tools[1].tool, "right");
  EXPECT_EQ(r.tool, "left");
  EXPECT_DOUBLE_EQ(r.force_max_n, r.tools[0].force_max_n);
  EXPECT_DOUBLE_EQ(r.tools[0].force_max_n, left->report().force_max_n);
  EXPECT_DOUBLE_EQ(r.tools[1].force_max_n, right->report().force_max_n);
  EXPECT_EQ(r.tools[0].contact_ticks, left->report().contact_ticks);
  EXPECT_EQ(r.tools[1].contact_ticks, right->report().contact_ticks);
  EXPECT_EQ(r.tools[1].haptic_ticks, 1000u);
  EXPECT_EQ(r.tools[1].device.max_force_n, 4.0);
  EXPECT_EQ(r.objects, 4) << "two objects and two tools";
  const std::string json = session_report_json(r);
  EXPECT_NE(json.find(R"("tool": "right")"), std::string::npos) << json;

  // the state per tool: the last published, after the end's zero
  EXPECT_EQ(both->state(1).tool, 1);
  EXPECT_EQ(both->state(1).haptic_ticks, 1000u);
  EXPECT_GT(both->state(1).tool_position_world.x, 0.14) << "the right hand is over the ball";
  EXPECT_LT(both->state(0).tool_position_world.x, 0.01);
}

// Contact events say which tool touched what.
TEST_F(MultiToolFixture, ContactEventsNameTheTool) {
  auto both = make(two_hands_scene_json("both"));
  ASSERT_TRUE(both);
  ASSERT_TRUE(both->run_stepped(0.6, 4));
  bool left_on_bunny = false, right_on_ball = false;
  ContactEvent e;
  while (both->poll_event(e)) {
    if (e.kind != ContactEventKind::kBegin) continue;
    EXPECT_TRUE((e.tool == 0 && e.object == 0) || (e.tool == 1 && e.object == 1))
        << "tool " << e.tool << " touched object " << e.object;
    left_on_bunny = left_on_bunny || (e.tool == 0 && e.object == 0);
    right_on_ball = right_on_ball || (e.tool == 1 && e.object == 1);
  }
  EXPECT_TRUE(left_on_bunny);
  EXPECT_TRUE(right_on_ball);
}

// the registry of the fault tests: sim-line, and "faulty-line", a sim-line that faults from its
// `fault_after`-th tick on; both record what they were commanded
struct FaultRegistry {
  std::vector<Vec3> healthy, faulty;
  haptico::DeviceRegistry registry = haptico::DeviceRegistry::with_simulated_devices();
  explicit FaultRegistry(std::int64_t fault_after) {
    healthy.reserve(20000);
    faulty.reserve(20000);
    const auto wrap = [](std::vector<Vec3>* log, std::int64_t after) {
      return [log, after](const haptico::DeviceConfig& c) -> Result<std::unique_ptr<haptico::HapticDevice>> {
        auto inner = haptico::DeviceRegistry::with_simulated_devices().create("sim-line", c);
        if (!inner) return inner.error();
        return std::unique_ptr<haptico::HapticDevice>(new FaultingDevice(std::move(*inner), after, log));
      };
    };
    EXPECT_TRUE(registry.register_driver("healthy-line", wrap(&healthy, -1)));
    EXPECT_TRUE(registry.register_driver("faulty-line", wrap(&faulty, fault_after)));
  }
};

std::string faulting_hands() {
  std::string json = two_hands_scene_json("both");
  json = testing::replaced(json, R"("driver": "sim-line")", R"("driver": "healthy-line")");
  return testing::replaced(json, R"("driver": "sim-line")", R"("driver": "faulty-line")");
}

// The right hand's device faults while both press: from that tick on both devices get zero, and
// the run ends with an error naming the tool and the device.
TEST_F(MultiToolFixture, AFaultOfOneDeviceZeroesBoth) {
  FaultRegistry devices(400);
  auto both = make(faulting_hands(), devices.registry);
  ASSERT_TRUE(both);
  const Status ran = both->run_stepped(1.0, 4);
  ASSERT_FALSE(ran);
  EXPECT_EQ(
      ran.error().message,
      "hands.json: tools[1] 'right': device 'sim-line' faulted: cable pulled; it was sent zero force; every "
      "device was sent zero force");
  EXPECT_TRUE(both->report().stopped_early);
  // ticks 1..400 ran normally; the right device's 401st read faulted and it got zero in that
  // tick. The left device's tick of that step had run already (each device has its own tick):
  // its next one, the first after the fault, is zero, and so is every one after it
  ASSERT_GE(devices.healthy.size(), 402u);
  ASSERT_GE(devices.faulty.size(), 401u);
  double healthy_before = 0.0;
  for (std::size_t i = 0; i <= 400; ++i) healthy_before = std::max(healthy_before, norm(devices.healthy[i]));
  EXPECT_GT(healthy_before, 0.5) << "the left hand was pressing when the right one faulted";
  for (std::size_t i = 401; i < devices.healthy.size(); ++i) EXPECT_EQ(norm(devices.healthy[i]), 0.0) << i;
  for (std::size_t i = 400; i < devices.faulty.size(); ++i) EXPECT_EQ(norm(devices.faulty[i]), 0.0) << i;
  EXPECT_EQ(both->report().tools[0].zeroed_ticks, 0u) << "the run ended with the faulted step";
}

// A fault of the device whose tick runs first: the other gets zero in its tick of the same step.
TEST_F(MultiToolFixture, AFaultOfTheFirstDeviceZeroesTheSecond) {
  FaultRegistry devices(380);  // the right hand is 9 mm into the ball then
  std::string json = two_hands_scene_json("both");
  json = testing::replaced(json, R"("driver": "sim-line")", R"("driver": "faulty-line")");
  json = testing::replaced(json, R"("driver": "sim-line")", R"("driver": "healthy-line")");
  auto both = make(json, devices.registry);
  ASSERT_TRUE(both);
  const Status ran = both->run_stepped(1.0, 4);
  ASSERT_FALSE(ran);
  EXPECT_NE(ran.error().message.find("tools[0] 'left': device 'sim-line' faulted: cable pulled"),
            std::string::npos)
      << ran.error().message;
  ASSERT_GE(devices.healthy.size(), 381u);
  for (std::size_t i = 380; i < devices.healthy.size(); ++i) EXPECT_EQ(norm(devices.healthy[i]), 0.0) << i;
  for (std::size_t i = 380; i < devices.faulty.size(); ++i) EXPECT_EQ(norm(devices.faulty[i]), 0.0) << i;
  EXPECT_GT(norm(devices.healthy[379]), 0.2) << "the right hand pressed into the ball until then";
  EXPECT_EQ(both->report().tools[1].zeroed_ticks, 1u)
      << "its tick of the faulted step, zeroed by the other's fault";
}

}  // namespace
}  // namespace uh::controllers
