#include "uh/museum/sighted_bot.hpp"

#include <gtest/gtest.h>

#include <random>

#include "test_levels.hpp"

namespace uh::museum {
namespace {

TEST(MuseumSightedBot, RoutesStayOnTheFloor) {
  for (const Difficulty d : {Difficulty::easy, Difficulty::hard}) {
    const Level level = make_level(d);
    const SightedBot bot(level);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> x(0.0, 28.0);
    std::uniform_real_distribution<double> y(0.0, 15.0);
    int routes = 0;
    while (routes < 300) {
      const Vec2 a{x(rng), y(rng)};
      const Vec2 b{x(rng), y(rng)};
      if (!walkable(level, a) || !walkable(level, b)) {
        EXPECT_TRUE(bot.route(a, b).empty() || (walkable(level, a) && walkable(level, b)));
        continue;
      }
      const std::vector<Vec2> way = bot.route(a, b);
      ASSERT_FALSE(way.empty()) << "every room is reachable";
      EXPECT_EQ(way.back(), b);
      Vec2 from = a;
      for (const Vec2& p : way) {
        EXPECT_TRUE(clear_path(level, from, p)) << from.x << "," << from.y << " -> " << p.x << "," << p.y;
        from = p;
      }
      ++routes;
    }
  }
  // the two rooms of the test level: through the doorway
  const Level two = test::two_rooms();
  const std::vector<Vec2> way = SightedBot(two).route({2.0, 2.0}, {15.0, 8.0});
  ASSERT_EQ(way.size(), 3u);
  EXPECT_TRUE(walkable(two, way[0]) && way[0].x > 8.4 && way[0].x < 9.6);
}

// a round of the bot with a Phantom that always knows the truth; returns the end state
GameState play(const Level& level, std::uint64_t seed) {
  GameState s = new_game(level, seed);
  SightedBot bot(level);
  Events events;
  while (s.phase == Phase::playing) {
    TickInput in{.vive = bot.decide(s)};
    if (s.table_count > 0)
      in.verdict =
          s.items[static_cast<std::size_t>(s.table[0])].genuine ? Verdict::genuine : Verdict::forgery;
    step(level, s, in, events);
  }
  return s;
}

TEST(MuseumSightedBot, FetchesEveryTargetOnAnOpenHall) {
  Level level = test::open_hall(4);
  level.cases = {{{6.0, 8.0}}, {{12.0, 2.0}}, {{18.0, 8.0}}, {{15.0, 5.0}}};
  const GameState s = play(level, 2);
  EXPECT_TRUE(s.ended_early);
  EXPECT_EQ(s.score.genuine_kept, 2);
  EXPECT_EQ(s.score.forgeries_rejected, 2);
  EXPECT_EQ(s.vive.times_caught, 0);
}

TEST(MuseumSightedBot, FinishesEasyRoundsPastTheGuards) {
  const Level level = make_level(Difficulty::easy);
  int finished = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const GameState s = play(level, seed);
    finished += s.ended_early ? 1 : 0;
    EXPECT_EQ(s.score.forgeries_kept, 0);
    EXPECT_EQ(s.score.genuine_kept, s.ended_early ? level.target_count : s.score.genuine_kept) << seed;
  }
  EXPECT_GE(finished, 5) << "the bot brings every piece in before the time runs out";
}

}  // namespace
}  // namespace uh::museum
