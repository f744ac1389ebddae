#include "uh/controllers/haptic_session.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include <sstream>

#include "scene_test_support.hpp"
#include "uh/forcecomp/virtual_coupling.hpp"

namespace uh::controllers {
namespace {

using testing::parse_trace;
using testing::replaced;
using testing::small_scene_json;
using testing::small_scene_with_limits;
using testing::test_assets;

struct SessionFixture : ::testing::Test {
  static void SetUpTestSuite() { cache_ = new std::filesystem::path(testing::fresh_cache("session")); }
  static void TearDownTestSuite() {
    std::filesystem::remove_all(*cache_);
    delete cache_;
  }
  static std::unique_ptr<HapticSession> make(const std::string& json, SessionOptions options = {}) {
    auto scene = parse_scene(json, "small.json", test_assets());
    EXPECT_TRUE(scene.has_value()) << scene.error().message;
    options.cache_dir = *cache_;
    auto session = HapticSession::create(*scene, options);
    EXPECT_TRUE(session.has_value()) << session.error().message;
    return session ? std::move(session).value() : nullptr;
  }
  static std::filesystem::path* cache_;
};
std::filesystem::path* SessionFixture::cache_ = nullptr;

// The penalty path, for the tests of its own mechanisms (held frames, the local model, the
// damping's onset, the rate limit at a held frame's step): the proxy, the default, has none of them.
SessionOptions penalty_path() {
  SessionOptions options;
  options.proxy = false;
  return options;
}

TEST_F(SessionFixture, SteppedSessionPushesTheToolOutAndIsDeterministic) {
  auto first = make(small_scene_json());
  ASSERT_TRUE(first);
  std::ostringstream trace_a;
  ASSERT_TRUE(first->run_stepped(1.0, 4, &trace_a).has_value());
  const SessionReport a = first->report();

  EXPECT_EQ(a.haptic_ticks, 1000u);
  EXPECT_EQ(a.collision_steps, 250u);
  EXPECT_GT(a.contact_ticks, 100u) << "the stylus goes 2.5 cm into the bunny";
  EXPECT_LT(a.contact_ticks, 1000u) << "and starts above it";
  EXPECT_GT(a.force_max_n, 0.5);
  EXPECT_LE(a.force_max_n, 6.0 + 1e-9) << "never above the scene's limit";
  EXPECT_EQ(a.force_nonfinite, 0u);
  ASSERT_EQ(a.timeline.size(), 1000u);

  auto second = make(small_scene_json());
  ASSERT_TRUE(second);
  std::ostringstream trace_b;
  ASSERT_TRUE(second->run_stepped(1.0, 4, &trace_b).has_value());
  const SessionReport& b = second->report();
  EXPECT_EQ(trace_a.str(), trace_b.str()) << "a stepped session is bit-for-bit repeatable";
  EXPECT_EQ(a.force_max_n, b.force_max_n);
  EXPECT_EQ(a.contact_ticks, b.contact_ticks);
  EXPECT_EQ(a.work_on_hand_j, b.work_on_hand_j);
}

TEST_F(SessionFixture, ForceOnTheStylusPointsUpOutOfTheBunny) {
  auto session = make(small_scene_json());
  ASSERT_TRUE(session);
  std::ostringstream trace;
  ASSERT_TRUE(session->run_stepped(0.5, 1, &trace).has_value());
  const auto table = parse_trace(trace.str());
  int pushing = 0, contact = 0;
  for (std::size_t i = 0; i < table.rows.size(); ++i) {
    const Vec3 f = table.force(i);
    if (std::abs(f.z) + std::abs(f.x) < 1e-3) continue;
    ++contact;
    if (f.z > std::abs(f.x)) ++pushing;
  }
  EXPECT_GT(contact, 50);
  EXPECT_GT(pushing, contact * 9 / 10) << "the force lifts the stylus out of the bunny";
}

TEST_F(SessionFixture, MultiRateReevaluationSmoothsTheForceOfASlowCollisionThread) {
  // collision every 8 ticks (125 Hz at a 1 kHz haptic rate): held forces step, re-evaluated ones follow
  auto multi = make(small_scene_json(true), penalty_path());
  auto held = make(small_scene_json(false), penalty_path());
  ASSERT_TRUE(multi && held);
  ASSERT_TRUE(multi->run_stepped(1.0, 8).has_value());
  ASSERT_TRUE(held->run_stepped(1.0, 8).has_value());
  EXPECT_GT(held->report().force_max_step_n, 0.0);
  EXPECT_LT(multi->report().force_max_step_n, 0.5 * held->report().force_max_step_n)
      << "multi-rate " << multi->report().force_max_step_n << " N vs held " << held->report().force_max_step_n << " N";
}

TEST_F(SessionFixture, LocalModelFollowsTheExactReevaluationOfEveryPair) {
  // collision every 4 ticks: the model (default) rendered, the exact re-evaluation run beside it
  SessionOptions check = penalty_path();
  check.check_model = true;
  SessionOptions reference = penalty_path();
  reference.tick_force = TickForce::kExact;
  auto checked = make(small_scene_json(), check);
  auto exact = make(small_scene_json(), reference);
  ASSERT_TRUE(checked && exact);
  ASSERT_TRUE(checked->run_stepped(1.0, 4).has_value());
  ASSERT_TRUE(exact->run_stepped(1.0, 4).has_value());
  const SessionReport& m = checked->report();
  const SessionReport& e = exact->report();
  EXPECT_EQ(m.tick_force, "model");
  EXPECT_EQ(e.tick_force, "exact");
  EXPECT_EQ(m.model_checked_ticks, 1000u);
  EXPECT_EQ(e.model_checked_ticks, 0u);
  ASSERT_GT(m.force_max_n, 0.5);
  EXPECT_GT(m.model_error_max_n, 0.0) << "a model is not the exact law";
  EXPECT_LT(m.model_error_rms_n, 0.02 * m.force_max_n);
  EXPECT_LT(m.model_error_max_n, 0.1 * m.force_max_n);
  EXPECT_NEAR(m.force_max_n, e.force_max_n, 0.05 * e.force_max_n);
  EXPECT_EQ(m.force_nonfinite, 0u);
}

TEST_F(SessionFixture, DampingFullVolumeRemovesTheKnockAtContactOnset) {
  // the stylus strikes the bunny at 0.11 m/s and keeps going in (the run ends before the line
  // does, so no turn-around changes the velocity); collision every tick, so that every force step
  // comes from the force law. The paper's damping reading puts eps_d * v on at the first touch.
  const std::string scene = replaced(small_scene_json(), R"("bounce": true)", R"("bounce": false)");
  auto with_paper = make(replaced(scene, R"("damping": 1.0,)", R"("damping": 1.0, "damping_full_volume": 0,)"),
                         penalty_path());
  auto ramped = make(scene, penalty_path());  // the default: damping_full_volume 2e-8 m^3
  auto undamped = make(replaced(scene, R"("damping": 1.0,)", R"("damping": 0.0,)"), penalty_path());
  ASSERT_TRUE(with_paper && ramped && undamped);
  for (auto* s : {with_paper.get(), ramped.get(), undamped.get()}) ASSERT_TRUE(s->run_stepped(0.45, 1).has_value());
  ASSERT_GT(undamped->report().contact_ticks, 50) << "the stylus must be in contact for a while";
  const double step_paper = with_paper->report().force_max_step_n;
  const double step_ramped = ramped->report().force_max_step_n;
  const double step_undamped = undamped->report().force_max_step_n;
  std::printf("largest force step: paper's damping reading %.4f N, ramped %.4f N, undamped %.4f N\n",
              step_paper, step_ramped, step_undamped);
  EXPECT_GT(step_paper, 2.0 * step_undamped) << "the onset knock must show, or this test proves nothing";
  EXPECT_LT(step_ramped, 0.5 * step_paper) << "ramped " << step_ramped << " N, paper " << step_paper << " N";
  EXPECT_LT(step_ramped, 1.5 * step_undamped) << "ramped " << step_ramped << " N, undamped " << step_undamped << " N";
}

TEST_F(SessionFixture, CouplingRendersThroughTheProxyAndStaysWithinLimits) {
  auto session = make(small_scene_json(true, true));
  ASSERT_TRUE(session);
  ASSERT_TRUE(session->run_stepped(1.0, 2).has_value());
  const auto& r = session->report();
  EXPECT_TRUE(r.coupling);
  EXPECT_GT(r.contact_ticks, 0u);
  EXPECT_GT(r.force_max_n, 0.1);
  EXPECT_LE(r.force_max_n, 6.0 + 1e-9);
  EXPECT_EQ(r.force_nonfinite, 0u);
}

TEST_F(SessionFixture, StateAfterASteppedRunIsTheZeroItEndedWith) {
  auto session = make(small_scene_json());
  ASSERT_TRUE(session);
  const SessionState before = session->state();
  EXPECT_EQ(before.haptic_ticks, 0u);
  std::ostringstream trace;
  std::vector<SessionState> published;
  auto seen = session->on_haptic_tick().connect([&](const SessionState& s) { published.push_back(s); });
  ASSERT_TRUE(session->run_stepped(0.5, 4, &trace).has_value());
  const SessionState s = session->state();
  const auto table = parse_trace(trace.str());
  // 500 ticks, then the zero the run ended with (not a tick)
  ASSERT_EQ(table.rows.size(), 501u);
  ASSERT_EQ(published.size(), 501u);
  EXPECT_EQ(table.flags(500), haptico::kTraceStopped);
  EXPECT_EQ(norm(table.force(500)), 0.0);
  EXPECT_EQ(s.haptic_ticks, 500u);
  EXPECT_EQ(norm(s.force_world), 0.0) << "the state shows the zero the device got last";
  // the last tick's state, as published, is the trace's last tick row
  const SessionState& tick = published[499];
  const std::vector<double>& last = table.rows[499];
  const auto at = [&](const char* name) { return last[static_cast<std::size_t>(table.column(name))]; };
  EXPECT_NEAR(tick.time_s, at("tick_time_s"), 1e-9);
  // the scene's workspace mapping is the identity: the handle is the device's pose, forces are the
  // device's (the tool, the proxy, rests on the bunny above the handle)
  EXPECT_NEAR(tick.handle_position_world.x, at("x"), 1e-9);
  EXPECT_NEAR(tick.handle_position_world.z, at("z"), 1e-9);
  EXPECT_GT(tick.tool_position_world.z, tick.handle_position_world.z) << "the proxy holds the tool out of the bunny";
  // (the proxy's turn is its own, no longer the device's: a unit quaternion still)
  const Quat& q = tick.tool_orientation_world;
  EXPECT_NEAR(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z, 1.0, 1e-9);
  EXPECT_NEAR(tick.force_world.z, at("fz"), 1e-6);
  EXPECT_NEAR(tick.torque_world.x, at("tx"), 1e-6);
  EXPECT_GT(norm(tick.force_world), 0.1) << "at 0.5 s the stylus is at its deepest in the bunny";
  EXPECT_GT(tick.contact_pairs, 0);
  EXPECT_EQ(tick.missed_deadlines, 0u);
  EXPECT_EQ(s.handle_position_world, tick.handle_position_world) << "the handle has not moved since";
  EXPECT_EQ(s.tool_position_world, tick.tool_position_world) << "nor the tool";
}

TEST_F(SessionFixture, StatesCarryTheDeviceButtons) {
  // a replayed trajectory presses button 0 at 0.1 s and buttons 1+2 at 0.2 s
  const auto file = *cache_ / "pressing.csv";
  {
    std::ofstream out(file);
    out << "time_s,x,y,z,qw,qx,qy,qz,buttons\n0,0,0,0.1,1,0,0,0,0\n0.1,0,0,0.09,1,0,0,0,1\n0.2,0,0,0.08,1,0,"
           "0,0,6\n";
  }
  const std::string scene =
      replaced(small_scene_json(), R"("driver": "sim-line",
                "config": { "start": [0.0, 0.0, 0.10], "end": [0.0, 0.0, 0.045], "duration_s": 0.5, "bounce": true,)",
               fmt::format(R"("driver": "sim-replay", "config": {{ "file": "{}",)", file.string()));
  auto session = make(scene);
  ASSERT_TRUE(session);
  std::vector<SessionState> published;
  auto seen = session->on_haptic_tick().connect([&](const SessionState& s) { published.push_back(s); });
  ASSERT_TRUE(session->run_stepped(0.3, 4).has_value());
  ASSERT_GE(published.size(), 300u);
  std::uint32_t union_of_masks = 0;
  for (const SessionState& s : published) {
    if (std::abs(s.time_s - 0.1) < 2e-3 || std::abs(s.time_s - 0.2) < 2e-3)
      continue;  // either side of a press
    const std::uint32_t expected = s.time_s < 0.1 ? 0u : (s.time_s < 0.2 ? 1u : 6u);
    EXPECT_EQ(s.buttons, expected) << "at " << s.time_s << " s";
    union_of_masks |= s.buttons;
  }
  EXPECT_EQ(union_of_masks, 7u);
}

// The small scene's stylus dips into the bunny and back: its contact events, on the penalty path
// or through the proxy, alternate and match the force's onsets and ends in the trace.
void expect_events_match_the_force(bool proxy) {
  SessionOptions options;
  options.proxy = proxy;
  auto session = SessionFixture::make(small_scene_json(), options);
  ASSERT_TRUE(session);
  ASSERT_TRUE(session->run_stepped(2.2, 1).has_value());
  std::vector<ContactEvent> events;
  for (ContactEvent e; session->poll_event(e);) events.push_back(e);
  // the stylus dips into the bunny and back twice in 2.2 s (0.5 s each way)
  ASSERT_GE(events.size(), 4u);
  EXPECT_EQ(session->dropped_events(), 0u);
  const auto& timeline = session->report().timeline;
  const auto force_at = [&](double t) {
    const auto k = static_cast<std::size_t>(std::llround(t * 1000.0));
    return k < timeline.size() ? timeline[k].force_n : 0.0;
  };
  for (std::size_t i = 0; i < events.size(); ++i) {
    const ContactEvent& e = events[i];
    SCOPED_TRACE(i);
    EXPECT_EQ(e.object, 0);
    EXPECT_EQ(e.kind, i % 2 == 0 ? ContactEventKind::kBegin : ContactEventKind::kEnd)
        << "begin and end alternate";
    if (i > 0) {
      EXPECT_GT(e.time_s, events[i - 1].time_s);
    }
    // an independent path: the force the haptic thread sent, from the trace
    if (e.kind == ContactEventKind::kBegin) {
      if (!proxy) {
        EXPECT_GT(e.volume, 0.0);  // the proxy rests on the surface: its rows, no overlap
      }
      EXPECT_GT(e.pairs, 0);
      EXPECT_EQ(force_at(e.time_s - 0.002), 0.0) << "no force before the overlap begins";
      EXPECT_GT(force_at(e.time_s + 0.002), 0.0) << "force once it has";
    } else {
      // (just before the end the damping of the withdrawing tool may already cancel the push)
      EXPECT_EQ(e.volume, 0.0);
      if (i > 0) {
        EXPECT_GT(force_at(0.5 * (events[i - 1].time_s + e.time_s)), 0.0) << "force during the contact";
      }
      EXPECT_EQ(force_at(e.time_s + 0.002), 0.0) << "none after it";
    }
  }
}

TEST_F(SessionFixture, ContactEventsAlternateAndMatchTheForceOnsets) { expect_events_match_the_force(false); }
TEST_F(SessionFixture, ContactEventsThroughTheProxyAlternateAndMatchTheForceOnsets) {
  expect_events_match_the_force(true);
}

TEST_F(SessionFixture, ASessionRunsOnceAndStopIsIdempotent) {
  auto session = make(small_scene_json());
  ASSERT_TRUE(session);
  EXPECT_TRUE(session->stop().has_value()) << "stop before any run does nothing";
  ASSERT_TRUE(session->run_stepped(0.1, 4).has_value());
  EXPECT_TRUE(session->stop().has_value());
  EXPECT_TRUE(session->stop().has_value());
  const Status again = session->start();
  ASSERT_FALSE(again.has_value());
  EXPECT_NE(again.error().message.find("runs once"), std::string::npos) << again.error().message;
  EXPECT_FALSE(session->run_stepped(0.1, 4).has_value());
  EXPECT_FALSE(session->running());
}

// The limit chain through the whole pipeline: the stylus pushed into the bunny asks for up to
// 6 N; whichever of the tool's, the session's and the device's limits is smallest bounds every
// tick, and only that limit is counted.
TEST_F(SessionFixture, SmallestOfToolSafetyAndDeviceLimitBoundsEveryTick) {
  struct Case {
    double tool, safety, device;
    double smallest;
    std::uint64_t haptico::LimitCounters::*counter;
  };
  const Case cases[] = {{1.0, 10.0, 6.0, 1.0, &haptico::LimitCounters::tool},
                        {2.0, 1.5, 6.0, 1.5, &haptico::LimitCounters::safety},
                        {2.0, 1.5, 1.2, 1.2, &haptico::LimitCounters::device}};
  for (const Case& c : cases) {
    auto session = make(small_scene_with_limits(c.tool, c.safety, c.device));
    ASSERT_TRUE(session);
    std::ostringstream trace;
    ASSERT_TRUE(session->run_stepped(1.0, 4, &trace).has_value());
    const SessionReport& r = session->report();
    const auto table = parse_trace(trace.str());
    ASSERT_EQ(table.rows.size(), 1001u) << "1000 ticks and the zero the run ended with";
    EXPECT_EQ(table.flags(1000), haptico::kTraceStopped);
    EXPECT_EQ(norm(table.force(1000)), 0.0);
    std::uint64_t clamped_rows = 0;
    for (std::size_t i = 0; i < table.rows.size(); ++i) {
      ASSERT_LE(norm(table.force(i)), c.smallest * (1 + 1e-12)) << "tick " << i << ", limit " << c.smallest;
      if ((table.flags(i) & haptico::kTraceForceClamped) != 0) ++clamped_rows;
    }
    EXPECT_LE(r.force_max_n, c.smallest * (1 + 1e-12));
    EXPECT_GT(r.force_max_n, 0.99 * c.smallest) << "the contact asks for more than the limit";
    EXPECT_GT(r.limits.*c.counter, 0u);
    EXPECT_EQ(r.limits.tool + r.limits.safety + r.limits.device, r.limits.*c.counter)
        << "only the smallest is counted";
    EXPECT_EQ(r.force_clamped, clamped_rows) << "the counters agree with the trace";
  }
}

// A late collision frame (one every 25 ticks, forces held between frames) would step the force;
// the rate limit spreads every change over ticks of at most rate / haptic rate.
TEST_F(SessionFixture, RateLimitBoundsEveryTickToTickStep) {
  const std::string held = replaced(small_scene_with_limits(6.0, 10.0, 6.0, 100.0), R"("multi_rate": true)",
                                    R"("multi_rate": false)");
  auto session = make(held, penalty_path());
  ASSERT_TRUE(session);
  std::ostringstream trace;
  ASSERT_TRUE(session->run_stepped(1.0, 25, &trace).has_value());
  const SessionReport& r = session->report();
  EXPECT_GT(r.force_max_raw_step_n, 0.5) << "held frames step the contact force";
  const auto table = parse_trace(trace.str());
  std::uint64_t limited_rows = 0;
  for (std::size_t i = 1; i < table.rows.size(); ++i) {
    EXPECT_LE(norm(table.force(i) - table.force(i - 1)), 0.1 * (1 + 1e-12)) << "tick " << i;
    if ((table.flags(i) & haptico::kTraceRateLimit) != 0) ++limited_rows;
  }
  EXPECT_LE(r.force_max_step_n, 0.1 * (1 + 1e-12));
  EXPECT_GT(r.limits.rate, 20u);
  EXPECT_EQ(r.limits.rate, limited_rows);
}

TEST_F(SessionFixture, UnknownDriverIsAnErrorNamingTheScene) {
  std::string json = small_scene_json();
  json.replace(json.find("sim-line"), 8, "phantom-omni");
  auto scene = parse_scene(json, "small.json", test_assets());
  ASSERT_TRUE(scene.has_value());
  SessionOptions options;
  options.cache_dir = *cache_;
  auto session = HapticSession::create(*scene, options);
  ASSERT_FALSE(session.has_value());
  EXPECT_NE(session.error().message.find("small.json: tool.device: unknown device driver 'phantom-omni'"), std::string::npos)
      << session.error().message;
}

TEST_F(SessionFixture, ReportJsonHasTheDocumentedFields) {
  auto session = make(small_scene_json());
  ASSERT_TRUE(session);
  ASSERT_TRUE(session->run_stepped(0.2, 4).has_value());
  const std::string json = session_report_json(session->report());
  for (const char* key : {"\"target_hz\"",     "\"rate_hz\"",    "\"ticks\"",       "\"missed_deadlines\"",
                          "\"jitter_us\"",     "\"p50\"",        "\"p99\"",         "\"max\"",
                          "\"min\"",           "\"median\"",     "\"query_us\"",    "\"max_n\"",
                          "\"max_torque_nm\"", "\"nonfinite\"",  "\"clamped\"",     "\"limited\"",
                          "\"device\"",        "\"tool\"",       "\"safety\"",      "\"contact\"",
                          "\"tick_us\"",       "\"tick_force\"", "\"error_rms_n\"", "\"held_ticks\""})
    EXPECT_NE(json.find(key), std::string::npos) << key;
}

// A simulated hand (sim-hand: the force acts back on its motion) presses the stylus deep into the
// bunny and pulls it out, twice: closed paths through deep contact, rendered through the virtual
// coupling. The coupling's stiffness is clamped to 90 % of the passive bound for the damping it is
// told the device has; `declared_device_damping` above the hand device's real 1 N s/m lets it
// exceed the real bound. The force-rate limit is off: it is a separate safety net that throttles
// what an active coupling can pump in, and this examines the coupling alone.
std::string hand_press_scene_json(double haptic_hz, double declared_device_damping) {
  return fmt::format(R"({{
  "name": "hand-press-test",
  "rates": {{ "haptic_hz": {haptic_hz}, "collision_hz": 1000 }},
  "seconds": 4.0,
  "objects": [{{ "name": "bunny", "mesh": "meshes/bunny_npm_3674.obj", "meters_per_unit": 0.01, "spheres": 600,
                "pose": {{ "rotation": [0.70710678, 0.70710678, 0, 0] }} }}],
  "tool": {{
    "name": "stylus", "mesh": "meshes/stylus.obj", "meters_per_unit": 0.01, "spheres": 150,
    "force": {{ "mode": "3dof", "stiffness": 2.0e4, "damping": 2.0, "mass_kg": 0.05,
               "center_of_mass": [0, 0, 0.025], "max_force_n": 8.0 }},
    "device": {{ "driver": "sim-hand",
                "config": {{ "target_start": [0.0, -0.01, 0.09], "target_end": [0.0, -0.01, 0.04], "duration_s": 1.0,
                            "bounce": true, "handle_mass_kg": 0.1, "hand_stiffness": 300, "hand_damping": 3.0,
                            "device_damping": 1.0, "substeps": 20, "max_force_n": 8 }} }}
  }},
  "force": {{ "safety": {{ "max_force_n": 8.0, "max_force_rate_n_per_s": 1.0e9 }},
             "coupling": {{ "enabled": true, "stiffness": 1.0e6, "device_damping": {declared},
                           "passivity_margin": 0.9, "proxy_mass_kg": 0.05 }} }}
}})",
                     fmt::arg("haptic_hz", haptic_hz), fmt::arg("declared", declared_device_damping));
}

TEST_F(SessionFixture, CouplingWithinThePassiveBoundPutsNoEnergyIntoAReactingHand) {
  for (const double hz : {1000.0, 4000.0}) {
    const int ticks_per_collision = static_cast<int>(hz / 1000.0);
    // within the bound for the device's real damping (1 N s/m): 0.9 * 2 b / T
    auto passive = make(hand_press_scene_json(hz, 1.0));
    ASSERT_TRUE(passive);
    ASSERT_TRUE(passive->run_stepped(4.0, ticks_per_collision).has_value());
    const SessionReport& p = passive->report();
    EXPECT_GT(p.contact_ticks, static_cast<std::uint64_t>(hz * 0.8)) << "the hand must press into the bunny";
    EXPECT_GT(p.force_max_n, 0.5) << hz << " Hz";
    EXPECT_LE(p.work_on_hand_j, 0.0) << hz << " Hz: a passive coupling put energy into the hand";

    // told the device has 10x its real damping, the coupling is 10x stiffer than the real bound
    // allows: the same motion now pumps energy into the hand, so the check above can fail
    auto active = make(hand_press_scene_json(hz, 10.0));
    ASSERT_TRUE(active);
    ASSERT_TRUE(active->run_stepped(4.0, ticks_per_collision).has_value());
    const double real_bound = forcecomp::max_passive_stiffness(1.0, 1.0 / hz, 0.0);
    EXPECT_GT(0.9 * forcecomp::max_passive_stiffness(10.0, 1.0 / hz, 0.0), 5.0 * real_bound);
    EXPECT_GT(active->report().work_on_hand_j, 0.01) << hz << " Hz: a coupling above the bound must show";
  }
}

}  // namespace
}  // namespace uh::controllers
