#include "uh/haptico/sim_replay_device.hpp"
#include "uh/haptico/trace_sample.hpp"

#include <gtest/gtest.h>

#include "text_mutation.hpp"

#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

namespace uh::haptico {
namespace {

Result<std::vector<TrajectorySample>> parse(const std::string& text) {
  std::istringstream in(text);
  return SimReplayDevice::parse_csv(in, "demo.csv");
}

std::string error_of(const std::string& text) {
  auto r = parse(text);
  EXPECT_FALSE(r.has_value()) << "parsed although invalid: " << text;
  return r ? std::string() : r.error().message;
}

TEST(SimReplayDevice, ReadsASessionTraceByColumnName) {
  // a `uh run --trace` file: many columns, device_time_s is the time, x..qz the pose
  std::ostringstream trace;
  write_trace_header(trace);
  for (int k = 0; k < 3; ++k) {
    TraceSample s;
    s.tick_time_s = 100.0 + 0.001 * k;
    s.state.time_s = 0.001 * k;
    s.state.position = {0.01 * k, -0.02, 0.03};
    s.state.orientation = normalized(Quat{1.0, 0.1 * k, 0.0, 0.0});
    s.sent.force = {1.0, 2.0, 3.0};
    write_trace_row(trace, s);
  }
  const auto r = parse(trace.str());
  ASSERT_TRUE(r.has_value()) << r.error().message;
  ASSERT_EQ(r->size(), 3u);
  EXPECT_DOUBLE_EQ((*r)[2].time_s, 0.002);
  EXPECT_NEAR((*r)[2].pose.position.x, 0.02, 1e-12);
  EXPECT_NEAR((*r)[2].pose.position.y, -0.02, 1e-12);
  EXPECT_NEAR((*r)[2].pose.rotation.x, normalized(Quat{1.0, 0.2, 0.0, 0.0}).x, 1e-9);
  // a header that lacks a pose column is still refused, with the expected columns named
  EXPECT_EQ(error_of("time_s,x,y,z,qw,qx,qy,extra\n0,0,0,0,1,0,0,0\n"),
            "demo.csv:1: the header lacks column 'qz' (expected columns time_s,x,y,z,qw,qx,qy,qz)");
  // rows must have as many fields as the header
  EXPECT_NE(error_of("extra,time_s,x,y,z,qw,qx,qy,qz\n7,0,0,0,0,1,0,0,0\n0.1,0,0,0,1,0,0,0\n").find("found 8 fields, expected 9"),
            std::string::npos);
}

TEST(SimReplayDevice, ParsesHeaderCommentsAndRows) {
  auto r = parse(
      "# recorded by hand\n"
      "time_s,x,y,z,qw,qx,qy,qz\n"
      "\n"
      "0.0, 0, 0, 0, 1, 0, 0, 0\n"
      "1.0, 0.1, 0, 0, 0, 0, 0, 2\r\n");
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_EQ(r->size(), 2u);
  EXPECT_EQ((*r)[1].pose.position, (Vec3{0.1, 0, 0}));
  EXPECT_EQ((*r)[1].pose.rotation, (Quat{0, 0, 0, 1}));  // normalised
}

TEST(SimReplayDevice, ErrorsNameFileAndLine) {
  EXPECT_EQ(error_of("0,0,0,0,1,0,0,0\n1,0,0,0,1,0,0\n"),
            "demo.csv:2: found 7 fields, expected 8 (time_s,x,y,z,qw,qx,qy,qz)");
  EXPECT_EQ(error_of("0,0,0,0,1,0,0,0\n1,0,abc,0,1,0,0,0\n"), "demo.csv:2: column 'y' (field 3) is 'abc', expected a finite number");
  EXPECT_EQ(error_of("0,0,0,0,1,0,0,0\n0,0,0,0,1,0,0,0\n"),
            "demo.csv:2: time 0 s is not after the previous sample's 0 s (times must increase)");
  EXPECT_EQ(error_of("t,x,y,z\n"),
            "demo.csv:1: the header lacks column 'time_s' (expected columns time_s,x,y,z,qw,qx,qy,qz)");
  EXPECT_EQ(error_of("# nothing\n"), "demo.csv: no samples (expected lines of 'time_s,x,y,z,qw,qx,qy,qz')");
  EXPECT_EQ(error_of("0,0,0,0,0,0,0,0\n"), "demo.csv:1: quaternion (qw,qx,qy,qz) must have a finite, non-zero length");
  // components that are finite but whose length overflows are refused too, not turned into zero
  EXPECT_EQ(error_of("0,0,0,0,1e300,1e300,0,0\n"),
            "demo.csv:1: quaternion (qw,qx,qy,qz) must have a finite, non-zero length");
  EXPECT_EQ(error_of("0,0,0,0,1,0,0,0\n1,nan,0,0,1,0,0,0\n"), "demo.csv:2: column 'x' (field 2) is 'nan', expected a finite number");
  // a header is only allowed before the first row
  EXPECT_EQ(error_of("0,0,0,0,1,0,0,0\ntime_s,x,y,z,qw,qx,qy,qz\n"),
            "demo.csv:2: column 'time_s' (field 1) is 'time_s', expected a finite number");
}

TEST(SimReplayDevice, MissingFileIsAnError) {
  auto r = SimReplayDevice::load_csv("/nonexistent/trajectory.csv");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().message, "/nonexistent/trajectory.csv: cannot open the trajectory file (No such file or directory)");
}

TEST(SimReplayDevice, InterpolatesAndHoldsLastPose) {
  auto r = parse("10,0,0,0,1,0,0,0\n10.1,0.01,0.02,0,1,0,0,0\n10.2,0.01,0.02,0.03,1,0,0,0\n");
  ASSERT_TRUE(r);
  SimReplayDevice d(*r, {});
  EXPECT_NEAR(d.duration_s(), 0.2, 1e-12);
  ASSERT_TRUE(d.open());
  for (int i = 0; i < 50; ++i) d.command({});  // t = 0.05 s after the first sample
  const DeviceState s = d.read_state();
  EXPECT_NEAR(s.position.x, 0.005, 1e-9);
  EXPECT_NEAR(s.position.y, 0.01, 1e-9);
  EXPECT_NEAR(s.linear_velocity.x, 0.1, 1e-6);
  for (int i = 0; i < 500; ++i) d.command({});
  const DeviceState end = d.read_state();
  EXPECT_EQ(end.position, (Vec3{0.01, 0.02, 0.03}));
}

TEST(SimReplayDevice, ScriptsButtonsHeldFromSampleToSample) {
  // a trace's buttons column is read by name; each mask holds until the next sample (no blending)
  std::ostringstream trace;
  write_trace_header(trace);
  const std::uint32_t masks[3] = {0, 1, 6};
  for (int k = 0; k < 3; ++k) {
    TraceSample s;
    s.state.time_s = 0.1 * k;
    s.state.orientation = Quat{};
    s.state.buttons = masks[k];
    write_trace_row(trace, s);
  }
  auto r = parse(trace.str());
  ASSERT_TRUE(r.has_value()) << r.error().message;
  ASSERT_EQ(r->size(), 3u);
  EXPECT_EQ((*r)[2].buttons, 6u);
  SimReplayDevice d(*r, {});
  ASSERT_TRUE(d.open());
  std::uint32_t seen[3] = {};
  for (int i = 0; i < 250; ++i) {  // 1 ms steps: 0.0 .. 0.249 s
    d.command({});
    const double t = 0.001 * (i + 1);
    if (std::abs(t - 0.1) < 1e-6 || std::abs(t - 0.2) < 1e-6) continue;  // either side of a step
    const std::uint32_t b = d.read_state().buttons;
    const int expected = t < 0.1 - 1e-9 ? 0 : (t < 0.2 - 1e-9 ? 1 : 2);
    EXPECT_EQ(b, masks[expected]) << "at " << t << " s";
    seen[expected] = b;
  }
  EXPECT_EQ(seen[1], 1u);
  EXPECT_EQ(seen[2], 6u);
  // a file without the column holds no buttons; a bad mask is refused with the line named
  EXPECT_EQ((*parse("0,0,0,0,1,0,0,0\n"))[0].buttons, 0u);
  EXPECT_EQ(error_of("time_s,x,y,z,qw,qx,qy,qz,buttons\n0,0,0,0,1,0,0,0,2.5\n"),
            "demo.csv:2: buttons 2.5 is not a bit mask (a whole number from 0 to 4294967295)");
  EXPECT_EQ(error_of("time_s,x,y,z,qw,qx,qy,qz,buttons\n0,0,0,0,1,0,0,0,-1\n"),
            "demo.csv:2: buttons -1 is not a bit mask (a whole number from 0 to 4294967295)");
}

TEST(SimReplayDevice, LoopsWhenAsked) {
  auto r = parse("0,0,0,0,1,0,0,0\n0.1,0.01,0,0,1,0,0,0\n");
  ASSERT_TRUE(r);
  SimReplayDevice d(*r, {.loop = true});
  ASSERT_TRUE(d.open());
  for (int i = 0; i < 125; ++i) d.command({});  // 1.25 periods
  EXPECT_NEAR(d.read_state().position.x, 0.0025, 1e-9);
}

TEST(SimReplayDevice, InterpolatesOrientationTheShortWay) {
  // q and -q are the same rotation: the halfway pose must be a quarter turn, not identity
  const Quat q90 = quat_from_axis_angle({0, 0, 1}, kPi / 2);
  std::ostringstream csv;
  csv << "0,0,0,0,1,0,0,0\n1,0,0,0," << -q90.w << ",0,0," << -q90.z << "\n";
  auto r = parse(csv.str());
  ASSERT_TRUE(r);
  SimReplayDevice d(*r, {});
  ASSERT_TRUE(d.open());
  for (int i = 0; i < 500; ++i) d.command({});
  const Quat q = d.read_state().orientation;
  const double angle = 2.0 * std::atan2(std::abs(q.z), std::abs(q.w));
  EXPECT_NEAR(angle, kPi / 4, 1e-6);
}

TEST(SimReplayDevice, RoundTripsRandomTrajectories) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    std::ostringstream csv;
    csv.precision(17);
    std::vector<TrajectorySample> written;
    double t = u(rng);
    for (int i = 0; i < 30; ++i) {
      t += 0.001 + 0.01 * (u(rng) + 1.0);
      const Quat q = normalized(Quat{u(rng), u(rng), u(rng), u(rng)});
      const Vec3 p{u(rng), u(rng), u(rng)};
      written.push_back({t, Pose{q, p}});
      csv << t << "," << p.x << "," << p.y << "," << p.z << "," << q.w << "," << q.x << "," << q.y << "," << q.z
          << "\n";
    }
    auto r = parse(csv.str());
    ASSERT_TRUE(r) << r.error().message;
    ASSERT_EQ(r->size(), written.size());
    for (std::size_t i = 0; i < written.size(); ++i) {
      EXPECT_EQ((*r)[i].time_s, written[i].time_s);
      EXPECT_EQ((*r)[i].pose.position, written[i].pose.position);
      EXPECT_NEAR((*r)[i].pose.rotation.w, written[i].pose.rotation.w, 1e-15);
    }
  }
}

TEST(SimReplayDevice, GarbageNeverCrashesAndErrorsNameTheSource) {
  // property: any mutation of a valid file either parses or gives an error that starts with the
  // file name (and, for row errors, the line)
  const std::string valid = "time_s,x,y,z,qw,qx,qy,qz\n0,0,0,0,1,0,0,0\n0.5,0.1,0.2,0.3,1,0,0,0\n1,0.1,0.2,0.3,0,1,0,0\n";
  const std::string alphabet = "0123456789.,-+eE\n #abcnaif";
  core::SplitMix64 rng{17};
  int errors = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const std::string text = test::mutate_text(valid, alphabet, rng);
    auto r = parse(text);
    if (!r) {
      ++errors;
      EXPECT_EQ(r.error().message.rfind("demo.csv:", 0), 0u) << r.error().message;
    } else {
      for (const TrajectorySample& s : *r) {
        EXPECT_TRUE(std::isfinite(s.time_s));
        EXPECT_TRUE(is_finite(s.pose.position));
        EXPECT_NEAR(s.pose.rotation.w * s.pose.rotation.w + s.pose.rotation.x * s.pose.rotation.x +
                        s.pose.rotation.y * s.pose.rotation.y + s.pose.rotation.z * s.pose.rotation.z,
                    1.0, 1e-9);
      }
    }
  }
  EXPECT_GT(errors, 100);
}

}  // namespace
}  // namespace uh::haptico
