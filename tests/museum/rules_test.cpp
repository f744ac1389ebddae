#include "uh/museum/rules.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>
#include <random>
#include <set>
#include <vector>

#include "test_levels.hpp"

namespace uh::museum {
namespace {

// steps `ticks` times with the same input; returns every event seen
std::vector<Event> run(const Level& level, GameState& state, const TickInput& input, int ticks = 1) {
  std::vector<Event> seen;
  Events events;
  for (int i = 0; i < ticks; ++i) {
    step(level, state, input, events);
    EXPECT_EQ(events.dropped, 0);
    seen.insert(seen.end(), events.list.begin(), events.list.begin() + events.count);
  }
  return seen;
}

int count_of(const std::vector<Event>& events, EventType type) {
  return static_cast<int>(
      std::count_if(events.begin(), events.end(), [&](const Event& e) { return e.type == type; }));
}

TickInput vive(ViveInput in) { return {.vive = in}; }

// a level with one guard standing watch at `post` (a route of two waypoints 1 cm apart, looking
// along +x at first)
Level with_guard(Level level, Vec2 post) {
  level.routes = {{{post, post + Vec2{0.01, 0.0}}}};
  return level;
}

// the state of a guard deal that does not depend on the seed: started at waypoint 0 facing +x
GameState guard_at_post(const Level& level, std::uint64_t seed = 1) {
  GameState state = new_game(level, seed);
  GuardState& g = state.guards[0];
  g.pos = level.routes[0].waypoints[0];
  g.next_waypoint = 1;
  g.direction = 1;
  g.facing = {1.0, 0.0};
  return state;
}

// makes a guard stand where it is, looking towards `where` for a minute (as after hearing a noise
// there through a wall)
void stand_watching(GuardState& guard, Vec2 where) {
  guard.mode = GuardMode::investigate;
  guard.noise_pos = where;
  guard.goal = guard.pos;
  guard.facing = normalized(where - guard.pos);
  guard.linger_left_s = 60.0;
  guard.trail = {};
  guard.trail[0] = guard.pos;
  guard.trail_count = 1;
}

TEST(MuseumRules, DealIsDeterministicFromTheSeed) {
  const Level level = make_level(Difficulty::hard);
  EXPECT_EQ(new_game(level, 42), new_game(level, 42));
  std::set<std::vector<int>> placements;
  for (std::uint64_t seed = 0; seed < 50; ++seed) {
    const GameState s = new_game(level, seed);
    ASSERT_EQ(s.target_count, level.target_count);
    ASSERT_EQ(s.item_count, 2 * s.target_count);
    std::set<int> kinds;
    std::set<int> cases;
    std::vector<int> genuine_cases;
    for (int t = 0; t < s.target_count; ++t) {
      kinds.insert(s.target_kinds[t]);
      const ItemState& a = s.items[2 * t];
      const ItemState& b = s.items[2 * t + 1];
      EXPECT_EQ(a.kind, s.target_kinds[t]);
      EXPECT_EQ(b.kind, s.target_kinds[t]);
      EXPECT_NE(a.genuine, b.genuine) << "one genuine piece and one forgery per target";
      genuine_cases.push_back(a.genuine ? a.case_index : b.case_index);
    }
    for (int i = 0; i < s.item_count; ++i) {
      cases.insert(s.items[i].case_index);
      EXPECT_EQ(s.case_item[s.items[i].case_index], i);
      EXPECT_EQ(s.items[i].place, ItemPlace::in_case);
    }
    EXPECT_EQ(static_cast<int>(kinds.size()), s.target_count) << "targets are different kinds";
    EXPECT_EQ(static_cast<int>(cases.size()), s.item_count) << "one item per case";
    for (int g = 0; g < s.guard_count; ++g) {
      const auto& w = level.routes[g].waypoints;
      EXPECT_NE(std::find(w.begin(), w.end(), s.guards[g].pos), w.end()) << "guards start on a waypoint";
    }
    placements.insert(genuine_cases);
  }
  EXPECT_GT(placements.size(), 40u) << "the seed decides where the genuine pieces are";
}

TEST(MuseumRules, SameInputsReplayBitForBit) {
  const Level level = make_level(Difficulty::hard);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<TickInput> inputs;
  for (int i = 0; i < 3000; ++i) {
    inputs.push_back({.vive = {.move = {u(rng), u(rng)},
                               .run = u(rng) > 0.3,
                               .break_case = u(rng) > 0.9,
                               .take = u(rng) > 0.8,
                               .deliver = u(rng) > 0.8},
                      .verdict = u(rng) > 0.9 ? Verdict::genuine : Verdict::none});
  }
  // Vive starts in the great hall among the guards, who cannot catch her in this test
  GameState a = new_game(level, 9);
  a.vive.pos = {12.0, 4.0};
  a.vive.grace_left_s = 1e9;
  GameState b = a;
  Events ea;
  Events eb;
  bool anything_heard = false;
  for (const TickInput& in : inputs) {
    step(level, a, in, ea);
    step(level, b, in, eb);
    ASSERT_EQ(a, b);
    ASSERT_EQ(ea.count, eb.count);
    for (int i = 0; i < ea.count; ++i) {
      ASSERT_EQ(ea.list[i], eb.list[i]);
      anything_heard = anything_heard || ea.list[i].type == EventType::guard_heard;
    }
  }
  EXPECT_GT(a.tick, 0);
  EXPECT_NE(a, new_game(level, 9));
  EXPECT_TRUE(anything_heard) << "the inputs reach the guards' rules";
}

TEST(MuseumRules, WalkingAndRunningSpeeds) {
  const Level level = test::open_hall();
  GameState s = new_game(level, 1);
  s.vive.pos = {5.0, 2.0};
  run(level, s, vive({.move = {1.0, 0.0}}), 60);
  EXPECT_NEAR(s.vive.pos.x, 5.0 + level.rules.walk_speed, 1e-9);
  EXPECT_FALSE(s.vive.running);
  run(level, s, vive({.move = {0.0, 1.0}, .run = true}), 60);
  EXPECT_NEAR(s.vive.pos.y, 2.0 + level.rules.run_speed, 1e-9);
  EXPECT_TRUE(s.vive.running);
  // a longer wish is no faster
  const Vec2 before = s.vive.pos;
  run(level, s, vive({.move = {3.0, 4.0}}), 60);
  EXPECT_NEAR(distance(s.vive.pos, before), level.rules.walk_speed, 1e-9);
  EXPECT_NEAR(s.vive.facing.x, 0.6, 1e-9);
  // a NaN wish stands still
  const Vec2 here = s.vive.pos;
  run(level, s, vive({.move = {std::nan(""), 1.0}}), 10);
  EXPECT_EQ(s.vive.pos, here);
}

TEST(MuseumRules, WallsStopViveWhoSlidesAlongThem) {
  const Level level = test::two_rooms();
  GameState s = new_game(level, 1);
  s.vive.pos = {8.0, 2.0};
  run(level, s, vive({.move = {1.0, 0.0}}), 120);
  EXPECT_NEAR(s.vive.pos.x, 9.0, level.rules.walk_speed * level.rules.tick_s);
  EXPECT_LE(s.vive.pos.x, 9.0);
  // pushing diagonally into the wall slides north along it
  run(level, s, vive({.move = {1.0, 1.0}}), 60);
  EXPECT_LE(s.vive.pos.x, 9.0);
  EXPECT_GT(s.vive.pos.y, 2.5);
  // through the doorway to the east room
  s.vive.pos = {8.0, 5.0};
  run(level, s, vive({.move = {1.0, 0.0}}), 240);
  EXPECT_GT(s.vive.pos.x, 10.5);
}

TEST(MuseumRules, RunningIsHeardWithinItsRadiusOnly) {
  const Level base = test::open_hall();
  const double r = base.rules.run_hear_radius;
  for (const double d : {r - 0.2, r + 0.2}) {
    const Level level = with_guard(base, {5.0, 8.0});
    GameState s = guard_at_post(level);
    // Vive runs east, just below the guard's post at distance d (one tick moves ~6 cm)
    s.vive.pos = {5.0 - 0.03, 8.0 - d};
    const auto events = run(level, s, vive({.move = {1.0, 0.0}, .run = true}));
    const bool heard = d < r;
    EXPECT_EQ(count_of(events, EventType::guard_heard), heard ? 1 : 0) << d;
    EXPECT_EQ(s.guards[0].mode, heard ? GuardMode::investigate : GuardMode::patrol) << d;
  }
  // walking right past is silent
  const Level level = with_guard(base, {5.0, 8.0});
  GameState s = guard_at_post(level);
  s.vive.pos = {4.0, 7.0};
  const auto events = run(level, s, vive({.move = {1.0, 0.0}}), 30);
  EXPECT_EQ(count_of(events, EventType::guard_heard), 0);
}

TEST(MuseumRules, BreakingGlassIsHeardWithinItsRadius) {
  const Level base = test::open_hall();
  const double r = base.rules.glass_hear_radius;
  // the case at (4, 5); a guard due north (looking away, east) at r -/+ 0.2 (in the hall: y <= 10,
  // so the hall grows for this test)
  for (const double d : {r - 0.2, r + 0.2}) {
    Level level = with_guard(base, {4.0, 5.0 + d});
    level.rooms[0].max.y = 20.0;
    GameState s = guard_at_post(level);
    s.vive.pos = {4.0, 4.5};
    const auto events = run(level, s, vive({.break_case = true}));
    ASSERT_EQ(count_of(events, EventType::case_broken), 1);
    EXPECT_TRUE(s.case_broken[0]);
    const bool heard = d < r;
    EXPECT_EQ(count_of(events, EventType::guard_heard), heard ? 1 : 0) << d;
    if (heard) {
      EXPECT_EQ(s.guards[0].noise_pos, (Vec2{4.0, 5.0}));
    }
  }
}

// independent reference for the view cone: angles from atan2
bool sees_reference(const Level& level, Vec2 guard, Vec2 facing, Vec2 target) {
  const Vec2 d = target - guard;
  if (norm(d) > level.rules.view_range) return false;
  double diff = std::atan2(d.y, d.x) - std::atan2(facing.y, facing.x);
  while (diff > std::numbers::pi) diff -= 2.0 * std::numbers::pi;
  while (diff < -std::numbers::pi) diff += 2.0 * std::numbers::pi;
  return std::fabs(diff) * 180.0 / std::numbers::pi <= level.rules.view_half_angle_deg;
}

TEST(MuseumRules, GuardsSeeWithinRangeAndConeMatchingAtan2) {
  const Level level = test::open_hall();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> x(0.0, 20.0);
  std::uniform_real_distribution<double> y(0.0, 10.0);
  std::uniform_real_distribution<double> angle(-std::numbers::pi, std::numbers::pi);
  int seen = 0;
  int tested = 0;
  for (int i = 0; i < 5000; ++i) {
    const Vec2 g{x(rng), y(rng)};
    const Vec2 t{x(rng), y(rng)};
    const double a = angle(rng);
    const Vec2 facing{std::cos(a), std::sin(a)};
    const bool ref = sees_reference(level, g, facing, t);
    // skip the boundaries, where rounding may go either way
    const Vec2 d = t - g;
    double diff = std::fabs(std::atan2(d.y, d.x) - a);
    diff = std::min(diff, 2.0 * std::numbers::pi - diff) * 180.0 / std::numbers::pi;
    if (std::fabs(diff - level.rules.view_half_angle_deg) < 1e-6 ||
        std::fabs(norm(d) - level.rules.view_range) < 1e-9)
      continue;
    EXPECT_EQ(guard_sees(level, g, facing, t), ref);
    seen += ref ? 1 : 0;
    ++tested;
  }
  EXPECT_GT(seen, 100);
  EXPECT_GT(tested - seen, 100);
}

TEST(MuseumRules, WallsBlockTheView) {
  const Level level = test::two_rooms();
  EXPECT_TRUE(guard_sees(level, {11.0, 5.0}, {-1.0, 0.0}, {8.0, 5.0}));   // through the doorway
  EXPECT_FALSE(guard_sees(level, {11.0, 3.0}, {-1.0, 0.0}, {8.0, 3.0}));  // through the wall
}

TEST(MuseumRules, TakingNeedsABrokenCaseAndCarriesAtMostTwo) {
  Level level = test::open_hall(4);  // cases at x = 4, 4.5, 5, 5.5 on y = 5
  GameState s = new_game(level, 5);
  s.vive.pos = {4.75, 4.5};  // every case within reach but the far ones at 1.0+ m
  auto events = run(level, s, vive({.take = true}));
  EXPECT_EQ(count_of(events, EventType::item_taken), 0) << "the glass is still whole";
  for (int i = 0; i < 4; ++i) run(level, s, vive({.break_case = true}));
  for (int c = 0; c < 4; ++c) EXPECT_TRUE(s.case_broken[c]) << c;
  events = run(level, s, vive({.take = true}), 3);
  EXPECT_EQ(count_of(events, EventType::item_taken), 2);
  EXPECT_EQ(s.vive.carried_count, kMaxCarried);
  int in_cases = 0;
  for (int i = 0; i < s.item_count; ++i) in_cases += s.items[i].place == ItemPlace::in_case ? 1 : 0;
  EXPECT_EQ(in_cases, 2);
  for (int i = 0; i < s.vive.carried_count; ++i)
    EXPECT_EQ(s.items[s.vive.carried[i]].place, ItemPlace::carried);
  // breaking an already broken case does nothing more
  events = run(level, s, vive({.break_case = true}));
  EXPECT_EQ(count_of(events, EventType::case_broken), 0);
}

TEST(MuseumRules, BreakingAnEmptyCaseSaysSo) {
  Level level = test::open_hall(2);
  level.cases.push_back({{10.0, 5.0}});  // a third case, empty: one target holds two items
  GameState s = new_game(level, 5);
  const int empty = s.case_item[0] < 0 ? 0 : (s.case_item[1] < 0 ? 1 : 2);
  s.vive.pos = level.cases[empty].pos - Vec2{0.0, 0.5};
  const auto events = run(level, s, vive({.break_case = true}));
  EXPECT_EQ(count_of(events, EventType::case_empty), 1);
}

TEST(MuseumRules, DeliveringNeedsTheTableWithinReach) {
  const Level level = test::open_hall();
  GameState s = new_game(level, 2);
  s.vive.pos = {4.25, 4.5};
  run(level, s, vive({.break_case = true}), 2);
  run(level, s, vive({.take = true}), 2);
  ASSERT_EQ(s.vive.carried_count, 2);
  const int first = s.vive.carried[0];
  const int second = s.vive.carried[1];
  auto events = run(level, s, vive({.deliver = true}));
  EXPECT_EQ(count_of(events, EventType::items_delivered), 0) << "too far from the table";
  s.vive.pos = level.table + Vec2{0.9, 0.0};
  events = run(level, s, vive({.deliver = true}));
  ASSERT_EQ(count_of(events, EventType::items_delivered), 1);
  EXPECT_EQ(s.vive.carried_count, 0);
  ASSERT_EQ(s.table_count, 2);
  EXPECT_EQ(s.table[0], first);
  EXPECT_EQ(s.table[1], second);
  EXPECT_EQ(s.items[first].place, ItemPlace::on_table);
}

TEST(MuseumRules, VerdictsScoreAndTheSummaryAgrees) {
  const Level level = test::open_hall(4);  // two targets
  GameState s = new_game(level, 8);
  // put all four pieces on the table: target 0's genuine, its forgery, target 1's forgery, its genuine
  auto piece = [&](int t, bool genuine) { return s.items[2 * t].genuine == genuine ? 2 * t : 2 * t + 1; };
  const int order[] = {piece(0, true), piece(0, false), piece(1, false), piece(1, true)};
  for (const int i : order) {
    s.items[i].place = ItemPlace::on_table;
    s.case_item[s.items[i].case_index] = -1;
    s.table[s.table_count++] = i;
  }
  // keep the genuine, keep the forgery, reject the forgery, reject the genuine
  const Verdict verdicts[] = {Verdict::genuine, Verdict::genuine, Verdict::forgery, Verdict::forgery};
  const bool correct[] = {true, false, true, false};
  for (int k = 0; k < 4; ++k) {
    const auto events = run(level, s, {.verdict = verdicts[k]});
    ASSERT_EQ(count_of(events, EventType::verdict), 1);
    const Event& e = *std::find_if(events.begin(), events.end(),
                                   [](const Event& ev) { return ev.type == EventType::verdict; });
    EXPECT_EQ(e.item, order[k]);
    EXPECT_EQ(e.correct, correct[k]) << k;
  }
  EXPECT_EQ(s.score.genuine_kept, 1);
  EXPECT_EQ(s.score.forgeries_kept, 1);
  EXPECT_EQ(s.score.forgeries_rejected, 1);
  EXPECT_EQ(s.score.genuine_rejected, 1);
  // both targets settled, nothing carried or on the table: the round ends early with a time bonus
  EXPECT_EQ(s.phase, Phase::ended);
  EXPECT_TRUE(s.ended_early);
  EXPECT_EQ(s.score.time_bonus, static_cast<int>(std::lround(s.time_left_s * level.rules.time_bonus_per_s)));
  EXPECT_EQ(s.score.points, level.rules.genuine_points - level.rules.forgery_penalty + s.score.time_bonus);
  const RoundSummary summary = summarize(level, s);
  EXPECT_EQ(summary.score, s.score);
  EXPECT_EQ(summary.targets[0].genuine_place, ItemPlace::kept);
  EXPECT_EQ(summary.targets[0].forgery_place, ItemPlace::kept);
  EXPECT_EQ(summary.targets[1].genuine_place, ItemPlace::rejected);
  EXPECT_EQ(summary.targets[1].forgery_place, ItemPlace::rejected);
  EXPECT_NEAR(summary.seconds_played, 4 * level.rules.tick_s, 1e-12);
  // a verdict with nothing on the table does nothing
  GameState empty = new_game(level, 8);
  const auto events = run(level, empty, {.verdict = Verdict::genuine});
  EXPECT_EQ(count_of(events, EventType::verdict), 0);
}

TEST(MuseumRules, CaughtViveLosesTheCarriedItemsAndTime) {
  const Level level = with_guard(test::open_hall(), {10.0, 5.0});
  GameState s = guard_at_post(level);
  // the guard looks away while Vive breaks in and takes both pieces
  stand_watching(s.guards[0], {15.0, 5.0});
  s.vive.pos = {4.25, 4.5};
  run(level, s, vive({.break_case = true}), 2);
  run(level, s, vive({.take = true}), 2);
  ASSERT_EQ(s.vive.carried_count, 2);
  EXPECT_EQ(s.vive.times_caught, 0);
  // then turns round: Vive is 3 m in front of it
  const double time_before = s.time_left_s;
  s.vive.pos = {7.0, 5.0};
  stand_watching(s.guards[0], s.vive.pos);
  const auto events = run(level, s, {});
  ASSERT_EQ(count_of(events, EventType::vive_caught), 1);
  EXPECT_EQ(s.vive.carried_count, 0);
  EXPECT_EQ(s.vive.times_caught, 1);
  EXPECT_EQ(s.vive.pos, level.entrance);
  EXPECT_NEAR(s.time_left_s, time_before - level.rules.tick_s - level.rules.caught_penalty_s, 1e-9);
  for (int i = 0; i < s.item_count; ++i) {
    EXPECT_EQ(s.items[i].place, ItemPlace::in_case);
    EXPECT_EQ(s.case_item[s.items[i].case_index], i) << "back in its own case";
  }
  // grace: in plain view again at once, not caught again until it runs out
  s.vive.pos = {7.0, 5.0};
  stand_watching(s.guards[0], s.vive.pos);
  const int grace_ticks = static_cast<int>(level.rules.caught_grace_s / level.rules.tick_s);
  auto during = run(level, s, {}, grace_ticks - 2);
  EXPECT_EQ(count_of(during, EventType::vive_caught), 0);
  during = run(level, s, {}, 4);
  EXPECT_EQ(count_of(during, EventType::vive_caught), 1);
}

TEST(MuseumRules, AGuardWalksToANoiseLooksAroundAndReturnsToItsRound) {
  const Level base = test::open_hall();
  Level level = base;
  level.routes = {{{{10.0, 8.0}, {18.0, 8.0}}}};
  GameState s = guard_at_post(level);
  const Vec2 left_at = s.guards[0].pos;
  // a case breaking 3.5 m south, out of sight behind the guard's back
  level.cases[0].pos = {10.0, 4.5};
  s.vive.pos = {10.0, 3.8};
  run(level, s, vive({.break_case = true}));
  ASSERT_EQ(s.guards[0].mode, GuardMode::investigate);
  const double walk_s = 3.5 / level.rules.investigate_speed;
  // Vive steps away out of the cone (behind the guard as it arrives)
  s.vive.pos = {2.0, 9.0};
  run(level, s, {}, static_cast<int>(walk_s / level.rules.tick_s) + 2);
  EXPECT_NEAR(distance(s.guards[0].pos, {10.0, 4.5}), 0.0, 1e-9);
  EXPECT_EQ(s.guards[0].mode, GuardMode::investigate) << "looks around";
  run(level, s, {}, static_cast<int>(level.rules.linger_s / level.rules.tick_s) + 1);
  EXPECT_EQ(s.guards[0].mode, GuardMode::returning);
  run(level, s, {}, static_cast<int>(3.5 / level.rules.patrol_speed / level.rules.tick_s) + 2);
  EXPECT_EQ(s.guards[0].mode, GuardMode::patrol);
  EXPECT_NEAR(s.guards[0].pos.y, left_at.y, 0.1);
}

TEST(MuseumRules, AGuardHearingThroughAWallTurnsToLook) {
  Level level = test::two_rooms();
  level.routes = {{{{12.0, 2.0}, {12.0, 2.01}}}};
  level.cases[0].pos = {7.5, 2.0};  // 4.5 m west, behind the wall
  GameState s = guard_at_post(level);
  s.vive.pos = {7.5, 1.2};
  run(level, s, vive({.break_case = true}));
  const GuardState& g = s.guards[0];
  ASSERT_EQ(g.mode, GuardMode::investigate);
  EXPECT_EQ(g.goal, (Vec2{12.0, 2.0})) << "it does not walk through the wall";
  run(level, s, {}, 5);
  EXPECT_EQ(s.guards[0].pos, (Vec2{12.0, 2.0}));
  EXPECT_NEAR(s.guards[0].facing.x, -1.0, 1e-9);
}

TEST(MuseumRules, TheTimerWarnsAndEndsTheRound) {
  Level level = test::open_hall();
  level.rules.round_s = 61.0;
  GameState s = new_game(level, 1);
  std::vector<int> warnings;
  int ended = 0;
  Events events;
  for (int i = 0; i < 62 * 60 && s.phase == Phase::playing; ++i) {
    step(level, s, {}, events);
    for (int k = 0; k < events.count; ++k) {
      if (events.list[k].type == EventType::time_warning) warnings.push_back(events.list[k].count);
      if (events.list[k].type == EventType::round_ended) ++ended;
    }
  }
  EXPECT_EQ(warnings, (std::vector<int>{60, 30, 10}));
  EXPECT_EQ(ended, 1);
  EXPECT_EQ(s.phase, Phase::ended);
  EXPECT_FALSE(s.ended_early);
  EXPECT_EQ(s.score.time_bonus, 0);
  EXPECT_NEAR(static_cast<double>(s.tick) * level.rules.tick_s, 61.0, 2 * level.rules.tick_s);
  // an ended round no longer changes
  const GameState end = s;
  run(level, s, vive({.move = {1.0, 0.0}}), 10);
  EXPECT_EQ(s, end);
}

TEST(MuseumRules, APausedRoundDoesNotChange) {
  const Level level = make_level(Difficulty::easy);
  GameState s = new_game(level, 4);
  run(level, s, vive({.move = {1.0, 0.0}}), 30);
  s.paused = true;
  const GameState paused = s;
  const auto events = run(level, s, vive({.move = {1.0, 0.0}, .run = true, .break_case = true}), 120);
  EXPECT_TRUE(events.empty());
  EXPECT_EQ(s, paused);
  s.paused = false;
  run(level, s, vive({.move = {1.0, 0.0}}), 1);
  EXPECT_EQ(s.tick, paused.tick + 1);
}

}  // namespace
}  // namespace uh::museum
