#include "uh/museum/level.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <utility>
#include <vector>

#include "test_levels.hpp"

namespace uh::museum {
namespace {

TEST(MuseumLevel, ShippedLevelsValidate) {
  for (const Difficulty d : {Difficulty::easy, Difficulty::hard}) {
    const Level level = make_level(d);
    const Status status = validate(level);
    EXPECT_TRUE(status.has_value()) << (status ? "" : status.error().message);
    EXPECT_GE(level.artifact_kinds.size(), 6u);
  }
}

TEST(MuseumLevel, HardHasMoreGuardsTargetsAndSharperSenses) {
  const Level easy = make_level(Difficulty::easy);
  const Level hard = make_level(Difficulty::hard);
  EXPECT_GT(hard.routes.size(), easy.routes.size());
  EXPECT_GT(hard.target_count, easy.target_count);
  EXPECT_GT(hard.rules.run_hear_radius, easy.rules.run_hear_radius);
  EXPECT_GT(hard.rules.glass_hear_radius, easy.rules.glass_hear_radius);
  EXPECT_GT(hard.rules.view_range, easy.rules.view_range);
  EXPECT_GT(hard.rules.view_half_angle_deg, easy.rules.view_half_angle_deg);
  EXPECT_LT(hard.rules.round_s, easy.rules.round_s);
}

// what validate() says about a broken level, or "" when it passes
std::string problem(const Level& level) {
  const Status s = validate(level);
  return s ? "" : s.error().message;
}

TEST(MuseumLevel, ValidateNamesWhatIsWrong) {
  EXPECT_EQ(problem(test::open_hall()), "");
  Level level = test::open_hall();
  level.cases[1].pos = {30.0, 5.0};
  EXPECT_NE(problem(level).find("case 1 at (30, 5) is not on the floor"), std::string::npos)
      << problem(level);

  level = test::two_rooms();
  level.routes = {{{{2.0, 2.0}, {15.0, 2.0}}}};
  EXPECT_NE(problem(level).find("patrol route 0 goes through a wall from (2, 2) to (15, 2)"),
            std::string::npos)
      << problem(level);

  level = test::open_hall();
  level.target_count = 2;
  EXPECT_NE(problem(level).find("2 cases cannot hold a genuine piece and a forgery for each of 2 targets"),
            std::string::npos)
      << problem(level);

  level = test::open_hall();
  level.rules.run_speed = -1.0;
  EXPECT_NE(problem(level).find("rules.run_speed is -1, must be positive"), std::string::npos)
      << problem(level);

  level = test::open_hall();
  level.table = {-1.0, 0.0};
  EXPECT_NE(problem(level).find("Phantom's table (-1, 0) is not on the floor"), std::string::npos)
      << problem(level);

  level = test::open_hall();
  level.rooms[0].max = level.rooms[0].min;
  EXPECT_NE(problem(level).find("room 'hall' is not a rectangle"), std::string::npos) << problem(level);
}

// independent reference for clear_path: clip the segment to every room (Liang-Barsky), merge the
// parameter intervals and return the longest stretch of the segment off the floor [m]
double longest_gap(const Level& level, Vec2 a, Vec2 b) {
  std::vector<std::pair<double, double>> on;
  const Vec2 d = b - a;
  for (const Room& room : level.rooms) {
    double t0 = 0.0;
    double t1 = 1.0;
    bool inside = true;
    const double p[] = {-d.x, d.x, -d.y, d.y};
    const double q[] = {a.x - room.min.x, room.max.x - a.x, a.y - room.min.y, room.max.y - a.y};
    for (int i = 0; i < 4 && inside; ++i) {
      if (p[i] == 0.0) {
        inside = q[i] >= 0.0;
      } else if (p[i] < 0.0) {
        t0 = std::max(t0, q[i] / p[i]);
      } else {
        t1 = std::min(t1, q[i] / p[i]);
      }
    }
    if (inside && t0 <= t1) on.emplace_back(t0, t1);
  }
  std::sort(on.begin(), on.end());
  double covered_to = 0.0;
  double gap = 0.0;
  for (const auto& [t0, t1] : on) {
    if (t0 > covered_to) gap = std::max(gap, t0 - covered_to);
    covered_to = std::max(covered_to, t1);
  }
  gap = std::max(gap, 1.0 - covered_to);
  return gap * norm(d);
}

TEST(MuseumLevel, ClearPathMatchesExactClipping) {
  for (const Difficulty difficulty : {Difficulty::easy, Difficulty::hard}) {
    const Level level = make_level(difficulty);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> x(-1.0, 29.0);
    std::uniform_real_distribution<double> y(-1.0, 16.0);
    int clear = 0;
    int blocked = 0;
    for (int i = 0; i < 4000; ++i) {
      const Vec2 a{x(rng), y(rng)};
      const Vec2 b{x(rng), y(rng)};
      const double gap = longest_gap(level, a, b);
      // a gap shorter than the 2 cm sampling step may slip between samples (a corner clipped)
      if (gap > 0.0 && gap < 0.02) continue;
      EXPECT_EQ(clear_path(level, a, b), gap == 0.0) << a.x << "," << a.y << " -> " << b.x << "," << b.y;
      ++(gap == 0.0 ? clear : blocked);
    }
    // both answers occur often enough for the comparison to mean something
    EXPECT_GT(clear, 100);
    EXPECT_GT(blocked, 100);
  }
}

TEST(MuseumLevel, DoorwayJoinsRoomsAndWallSeparatesThem) {
  const Level level = test::two_rooms();
  EXPECT_TRUE(walkable(level, {9.5, 5.0}));
  EXPECT_FALSE(walkable(level, {9.5, 3.0}));
  EXPECT_TRUE(clear_path(level, {5.0, 5.0}, {15.0, 5.0}));
  EXPECT_FALSE(clear_path(level, {5.0, 2.0}, {15.0, 2.0}));
}

}  // namespace
}  // namespace uh::museum
