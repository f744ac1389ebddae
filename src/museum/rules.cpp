#include "uh/museum/rules.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numbers>

#include "uh/core/split_mix.hpp"

namespace uh::museum {

const char* to_string(ItemPlace place) {
  switch (place) {
    case ItemPlace::in_case:
      return "in_case";
    case ItemPlace::carried:
      return "carried";
    case ItemPlace::on_table:
      return "on_table";
    case ItemPlace::kept:
      return "kept";
    case ItemPlace::rejected:
      return "rejected";
  }
  return "unknown";
}

const char* to_string(GuardMode mode) {
  switch (mode) {
    case GuardMode::patrol:
      return "patrol";
    case GuardMode::investigate:
      return "investigate";
    case GuardMode::returning:
      return "returning";
  }
  return "unknown";
}

const char* to_string(Phase phase) {
  switch (phase) {
    case Phase::playing:
      return "playing";
    case Phase::ended:
      return "ended";
  }
  return "unknown";
}

const char* to_string(Verdict verdict) {
  switch (verdict) {
    case Verdict::none:
      return "none";
    case Verdict::genuine:
      return "genuine";
    case Verdict::forgery:
      return "forgery";
  }
  return "unknown";
}

const char* to_string(EventType type) {
  switch (type) {
    case EventType::case_broken:
      return "case_broken";
    case EventType::case_empty:
      return "case_empty";
    case EventType::item_taken:
      return "item_taken";
    case EventType::items_delivered:
      return "items_delivered";
    case EventType::guard_heard:
      return "guard_heard";
    case EventType::vive_caught:
      return "vive_caught";
    case EventType::verdict:
      return "verdict";
    case EventType::time_warning:
      return "time_warning";
    case EventType::round_ended:
      return "round_ended";
  }
  return "unknown";
}

namespace {

// Fisher-Yates over the first `count` entries, dealt by the seed's generator
void shuffle(core::SplitMix64& random, int* first, int count) {
  for (int i = count - 1; i > 0; --i) std::swap(first[i], first[random.below(i + 1)]);
}

template <typename T, std::size_t N>
T& at(std::array<T, N>& a, int i) {
  return a[static_cast<std::size_t>(i)];
}
template <typename T, std::size_t N>
const T& at(const std::array<T, N>& a, int i) {
  return a[static_cast<std::size_t>(i)];
}
template <typename T>
const T& at(const std::vector<T>& v, int i) {
  return v[static_cast<std::size_t>(i)];
}

struct Noise {
  Vec2 pos{};
  double radius = 0.0;
};
struct Noises {
  std::array<Noise, 2> list{};  // running and one glass per tick at most
  int count = 0;
  void push(Noise n) {
    if (count < static_cast<int>(list.size())) at(list, count++) = n;
  }
};

// moves `pos` towards `goal` by at most `max_step`; returns whether it arrived
bool walk_towards(Vec2& pos, Vec2& facing, Vec2 goal, double max_step) {
  const Vec2 to_goal = goal - pos;
  const double d = norm(to_goal);
  if (d > 0.0) facing = to_goal * (1.0 / d);
  if (d <= max_step) {
    pos = goal;
    return true;
  }
  pos += facing * max_step;
  return false;
}

// Vive's movement: where the floor ends, slide along the wall on the axis that stays on the floor
void move_vive(const Level& level, ViveState& vive, Vec2 delta) {
  const Vec2 from = vive.pos;
  const Vec2 candidates[] = {from + delta, {from.x + delta.x, from.y}, {from.x, from.y + delta.y}};
  for (const Vec2& to : candidates) {
    if (walkable(level, to)) {
      vive.pos = to;
      break;
    }
  }
  const Vec2 moved = vive.pos - from;
  if (dot(moved, moved) > 0.0) vive.facing = normalized(moved);
}

// the nearest case within reach that passes `wanted`, or -1
template <typename Wanted>
int nearest_case(const Level& level, const GameState& state, Vec2 pos, Wanted wanted) {
  int best = -1;
  double best_d = level.rules.reach;
  for (int c = 0; c < state.case_count; ++c) {
    const double d = distance(at(level.cases, c).pos, pos);
    if (d <= best_d && wanted(c)) {
      best = c;
      best_d = d;
    }
  }
  return best;
}

void vive_actions(const Level& level, GameState& state, const ViveInput& in, Noises& noises, Events& events) {
  ViveState& vive = state.vive;
  if (in.break_case) {
    const int c = nearest_case(level, state, vive.pos, [&](int i) { return !at(state.case_broken, i); });
    if (c >= 0) {
      at(state.case_broken, c) = true;
      const Vec2 pos = at(level.cases, c).pos;
      noises.push({pos, level.rules.glass_hear_radius});
      events.push({.type = EventType::case_broken,
                   .case_index = c,
                   .pos = pos,
                   .radius = level.rules.glass_hear_radius});
      if (at(state.case_item, c) < 0)
        events.push({.type = EventType::case_empty, .case_index = c, .pos = pos});
    }
  }
  if (in.take && vive.carried_count < kMaxCarried) {
    const int c = nearest_case(level, state, vive.pos, [&](int i) {
      return at(state.case_broken, i) && at(state.case_item, i) >= 0;
    });
    if (c >= 0) {
      const int item = at(state.case_item, c);
      at(state.case_item, c) = -1;
      at(state.items, item).place = ItemPlace::carried;
      at(vive.carried, vive.carried_count++) = item;
      events.push(
          {.type = EventType::item_taken, .item = item, .case_index = c, .pos = at(level.cases, c).pos});
    }
  }
  if (in.deliver && vive.carried_count > 0 && distance(vive.pos, level.table) <= level.rules.reach) {
    for (int i = 0; i < vive.carried_count; ++i) {
      const int item = at(vive.carried, i);
      at(state.items, item).place = ItemPlace::on_table;
      at(state.table, state.table_count++) = item;
      at(vive.carried, i) = -1;
    }
    events.push({.type = EventType::items_delivered, .count = vive.carried_count, .pos = level.table});
    vive.carried_count = 0;
  }
}

void phantom_verdict(const Level& level, GameState& state, Verdict verdict, Events& events) {
  if (verdict == Verdict::none || state.table_count == 0) return;
  const int item_index = at(state.table, 0);
  for (int i = 1; i < state.table_count; ++i) at(state.table, i - 1) = at(state.table, i);
  at(state.table, --state.table_count) = 0;
  ItemState& item = at(state.items, item_index);
  const bool keep = verdict == Verdict::genuine;
  item.place = keep ? ItemPlace::kept : ItemPlace::rejected;
  Score& s = state.score;
  if (keep && item.genuine) {
    ++s.genuine_kept;
    s.points += level.rules.genuine_points;
  } else if (keep) {
    ++s.forgeries_kept;
    s.points -= level.rules.forgery_penalty;
  } else if (item.genuine) {
    ++s.genuine_rejected;
  } else {
    ++s.forgeries_rejected;
  }
  events.push(
      {.type = EventType::verdict, .item = item_index, .verdict = verdict, .correct = keep == item.genuine});
}

// a guard that hears a noise walks there when the way is clear (remembering where it turned, to
// walk back the same way) and otherwise turns to look from where it stands
void hear(const Level& level, GuardState& guard, int g, const Noise& noise, Events& events) {
  // a noise near the one it already walks to changes nothing (running is heard every tick)
  constexpr double kSameNoise = 1.0;  // [m]
  if (guard.mode == GuardMode::investigate && distance(noise.pos, guard.noise_pos) < kSameNoise) return;
  if (guard.mode == GuardMode::patrol) {
    guard.trail_count = 0;
  }
  const bool was_investigating = guard.mode == GuardMode::investigate;
  guard.mode = GuardMode::investigate;
  guard.noise_pos = noise.pos;
  guard.linger_left_s = level.rules.linger_s;
  const bool room_in_trail = guard.trail_count < kMaxTrail ||
                             (guard.trail_count > 0 && at(guard.trail, guard.trail_count - 1) == guard.pos);
  if (room_in_trail && clear_path(level, guard.pos, noise.pos)) {
    if (guard.trail_count == 0 || !(at(guard.trail, guard.trail_count - 1) == guard.pos)) {
      at(guard.trail, guard.trail_count++) = guard.pos;
    }
    guard.goal = noise.pos;
  } else {
    if (guard.trail_count == 0) at(guard.trail, guard.trail_count++) = guard.pos;
    guard.goal = guard.pos;
  }
  if (!was_investigating)
    events.push({.type = EventType::guard_heard, .guard = g, .pos = noise.pos, .radius = noise.radius});
}

void move_guard(const Level& level, GuardState& guard, int g, double dt) {
  const RuleNumbers& r = level.rules;
  switch (guard.mode) {
    case GuardMode::patrol: {
      const std::vector<Vec2>& w = at(level.routes, g).waypoints;
      const int n = static_cast<int>(w.size());
      if (walk_towards(guard.pos, guard.facing, at(w, guard.next_waypoint), r.patrol_speed * dt)) {
        guard.next_waypoint = (guard.next_waypoint + guard.direction + n) % n;
      }
      break;
    }
    case GuardMode::investigate:
      if (walk_towards(guard.pos, guard.facing, guard.goal, r.investigate_speed * dt)) {
        const Vec2 look = guard.noise_pos - guard.pos;
        if (dot(look, look) > 0.0) guard.facing = normalized(look);
        guard.linger_left_s -= dt;
        if (guard.linger_left_s <= 0.0) guard.mode = GuardMode::returning;
      }
      break;
    case GuardMode::returning:
      if (guard.trail_count == 0 ||
          walk_towards(guard.pos, guard.facing, at(guard.trail, guard.trail_count - 1),
                       r.patrol_speed * dt)) {
        if (guard.trail_count > 0) --guard.trail_count;
        if (guard.trail_count == 0) guard.mode = GuardMode::patrol;
      }
      break;
  }
}

void catch_vive(const Level& level, GameState& state, int g, Events& events) {
  ViveState& vive = state.vive;
  // the guards put what Vive carried back in its cases (broken ones stay broken)
  for (int i = 0; i < vive.carried_count; ++i) {
    const int item = at(vive.carried, i);
    ItemState& it = at(state.items, item);
    it.place = ItemPlace::in_case;
    at(state.case_item, it.case_index) = item;
    at(vive.carried, i) = -1;
  }
  events.push({.type = EventType::vive_caught, .guard = g, .count = vive.carried_count, .pos = vive.pos});
  vive.carried_count = 0;
  vive.pos = level.entrance;
  vive.running = false;
  vive.grace_left_s = level.rules.caught_grace_s;
  ++vive.times_caught;
  state.time_left_s = std::max(0.0, state.time_left_s - level.rules.caught_penalty_s);
}

void end_round(GameState& state, Events& events) {
  state.phase = Phase::ended;
  events.push({.type = EventType::round_ended, .count = state.score.points});
}

}  // namespace

GameState new_game(const Level& level, std::uint64_t seed) {
  assert(validate(level).has_value() && "uh::museum::new_game(): the level does not validate");
  GameState state;
  core::SplitMix64 rng{seed};
  state.seed = seed;
  state.time_left_s = level.rules.round_s;
  state.vive.pos = level.entrance;

  std::array<int, kMaxArtifactKinds> kinds{};
  const int kind_count = static_cast<int>(level.artifact_kinds.size());
  for (int k = 0; k < kind_count; ++k) at(kinds, k) = k;
  shuffle(rng, kinds.data(), kind_count);
  state.target_count = level.target_count;
  for (int t = 0; t < state.target_count; ++t) at(state.target_kinds, t) = at(kinds, t);

  state.case_count = static_cast<int>(level.cases.size());
  std::array<int, kMaxCases> cases{};
  for (int c = 0; c < state.case_count; ++c) {
    at(cases, c) = c;
    at(state.case_item, c) = -1;
  }
  shuffle(rng, cases.data(), state.case_count);
  state.item_count = 2 * state.target_count;
  for (int t = 0; t < state.target_count; ++t) {
    const bool genuine_first = (rng.next() & 1u) != 0;
    for (int j = 0; j < 2; ++j) {
      const int i = 2 * t + j;
      ItemState& item = at(state.items, i);
      item.kind = at(state.target_kinds, t);
      item.genuine = (j == 0) == genuine_first;
      item.case_index = at(cases, i);
      at(state.case_item, item.case_index) = i;
    }
  }

  state.guard_count = static_cast<int>(level.routes.size());
  for (int g = 0; g < state.guard_count; ++g) {
    const std::vector<Vec2>& w = at(level.routes, g).waypoints;
    const int n = static_cast<int>(w.size());
    GuardState& guard = at(state.guards, g);
    const int start = rng.below(n);
    guard.direction = (rng.next() & 1u) != 0 ? 1 : -1;
    guard.pos = at(w, start);
    guard.next_waypoint = (start + guard.direction + n) % n;
    guard.facing = normalized(at(w, guard.next_waypoint) - guard.pos);
  }
  return state;
}

bool guard_sees(const Level& level, Vec2 guard_pos, Vec2 facing, Vec2 target) {
  const Vec2 to_target = target - guard_pos;
  const double d = norm(to_target);
  if (d > level.rules.view_range) return false;
  if (d > 0.0) {
    const double cos_half = std::cos(level.rules.view_half_angle_deg * std::numbers::pi / 180.0);
    if (dot(to_target, facing) < cos_half * d * norm(facing)) return false;
  }
  return clear_path(level, guard_pos, target);
}

bool target_settled(const GameState& state, int target) {
  const ItemPlace a = at(state.items, 2 * target).place;
  const ItemPlace b = at(state.items, 2 * target + 1).place;
  return a == ItemPlace::kept || b == ItemPlace::kept ||
         (a == ItemPlace::rejected && b == ItemPlace::rejected);
}

void step(const Level& level, GameState& state, const TickInput& input, Events& events) {
  events.clear();
  if (state.paused || state.phase == Phase::ended) return;
  const RuleNumbers& r = level.rules;
  const double dt = r.tick_s;
  ++state.tick;

  const double before = state.time_left_s;
  state.time_left_s = std::max(0.0, state.time_left_s - dt);
  for (const int warning : {60, 30, 10}) {
    if (before > warning && state.time_left_s <= warning)
      events.push({.type = EventType::time_warning, .count = warning});
  }

  ViveState& vive = state.vive;
  vive.grace_left_s = std::max(0.0, vive.grace_left_s - dt);
  Vec2 wanted = input.vive.move;
  if (!std::isfinite(wanted.x) || !std::isfinite(wanted.y)) wanted = {};
  if (dot(wanted, wanted) > 1.0) wanted = normalized(wanted);
  const Vec2 from = vive.pos;
  move_vive(level, vive, wanted * ((input.vive.run ? r.run_speed : r.walk_speed) * dt));
  vive.running = input.vive.run && !(vive.pos == from);

  Noises noises;
  if (vive.running) noises.push({vive.pos, r.run_hear_radius});
  vive_actions(level, state, input.vive, noises, events);
  phantom_verdict(level, state, input.verdict, events);

  for (int g = 0; g < state.guard_count; ++g) {
    GuardState& guard = at(state.guards, g);
    // of this tick's noises within earshot, the guard goes for the nearest
    const Noise* heard = nullptr;
    for (int i = 0; i < noises.count; ++i) {
      const Noise& n = at(noises.list, i);
      if (distance(n.pos, guard.pos) <= n.radius &&
          (heard == nullptr || distance(n.pos, guard.pos) < distance(heard->pos, guard.pos))) {
        heard = &n;
      }
    }
    if (heard != nullptr) hear(level, guard, g, *heard, events);
    move_guard(level, guard, g, dt);
  }
  if (vive.grace_left_s <= 0.0) {
    for (int g = 0; g < state.guard_count; ++g) {
      const GuardState& guard = at(state.guards, g);
      if (guard_sees(level, guard.pos, guard.facing, vive.pos)) {
        catch_vive(level, state, g, events);
        break;
      }
    }
  }

  if (state.time_left_s <= 0.0) {
    end_round(state, events);
    return;
  }
  bool all_settled = vive.carried_count == 0 && state.table_count == 0;
  for (int t = 0; all_settled && t < state.target_count; ++t) all_settled = target_settled(state, t);
  if (all_settled) {
    state.ended_early = true;
    state.score.time_bonus = static_cast<int>(std::lround(state.time_left_s * r.time_bonus_per_s));
    state.score.points += state.score.time_bonus;
    end_round(state, events);
  }
}

RoundSummary summarize(const Level& level, const GameState& state) {
  RoundSummary summary;
  summary.target_count = state.target_count;
  for (int t = 0; t < state.target_count; ++t) {
    TargetOutcome& outcome = at(summary.targets, t);
    outcome.kind = at(state.target_kinds, t);
    for (int j = 0; j < 2; ++j) {
      const ItemState& item = at(state.items, 2 * t + j);
      (item.genuine ? outcome.genuine_place : outcome.forgery_place) = item.place;
    }
  }
  Score& s = summary.score;
  for (int i = 0; i < state.item_count; ++i) {
    const ItemState& item = at(state.items, i);
    if (item.place == ItemPlace::kept) ++(item.genuine ? s.genuine_kept : s.forgeries_kept);
    if (item.place == ItemPlace::rejected) ++(item.genuine ? s.genuine_rejected : s.forgeries_rejected);
  }
  if (state.ended_early)
    s.time_bonus = static_cast<int>(std::lround(state.time_left_s * level.rules.time_bonus_per_s));
  s.points = s.genuine_kept * level.rules.genuine_points - s.forgeries_kept * level.rules.forgery_penalty +
             s.time_bonus;
  summary.times_caught = state.vive.times_caught;
  summary.seconds_played = static_cast<double>(state.tick) * level.rules.tick_s;
  summary.ended_early = state.ended_early;
  return summary;
}

}  // namespace uh::museum
