#include "uh/museum/sighted_bot.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <numbers>

namespace uh::museum {
namespace {

bool contains(const Room& r, Vec2 p) {
  return p.x >= r.min.x && p.x <= r.max.x && p.y >= r.min.y && p.y <= r.max.y;
}

// the overlap of two rooms (a doorway's share of each), when it has an area
bool overlap(const Room& a, const Room& b, Vec2& centre) {
  const Vec2 lo{std::max(a.min.x, b.min.x), std::max(a.min.y, b.min.y)};
  const Vec2 hi{std::min(a.max.x, b.max.x), std::min(a.max.y, b.max.y)};
  if (!(lo.x < hi.x && lo.y < hi.y)) return false;
  centre = (lo + hi) * 0.5;
  return true;
}

double length(Vec2 from, const std::vector<Vec2>& path) {
  double total = 0.0;
  for (const Vec2& p : path) {
    total += distance(from, p);
    from = p;
  }
  return total;
}

// stand this close to a case or the table to act on it [m] (cases are metres apart, so it is
// then the nearest)
constexpr double kArrive = 0.4;
// wait at most this long for the guards to be out of earshot before breaking a case [ticks]
constexpr int kMaxWaitTicks = 480;

}  // namespace

SightedBot::SightedBot(const Level& level) : level_(level) {}

std::vector<Vec2> SightedBot::route(Vec2 from, Vec2 to) const {
  const int n = static_cast<int>(level_.rooms.size());
  // breadth-first over rooms joined by an overlap, from every room holding `from`
  std::vector<int> previous(static_cast<std::size_t>(n), -2);
  std::deque<int> open;
  for (int r = 0; r < n; ++r) {
    if (contains(level_.rooms[static_cast<std::size_t>(r)], from)) {
      previous[static_cast<std::size_t>(r)] = -1;
      open.push_back(r);
    }
  }
  int reached = -1;
  while (!open.empty() && reached < 0) {
    const int r = open.front();
    open.pop_front();
    if (contains(level_.rooms[static_cast<std::size_t>(r)], to)) {
      reached = r;
      break;
    }
    for (int s = 0; s < n; ++s) {
      Vec2 c;
      if (previous[static_cast<std::size_t>(s)] == -2 &&
          overlap(level_.rooms[static_cast<std::size_t>(r)], level_.rooms[static_cast<std::size_t>(s)], c)) {
        previous[static_cast<std::size_t>(s)] = r;
        open.push_back(s);
      }
    }
  }
  if (reached < 0) return {};
  // rooms are convex: from one doorway's centre to the next stays inside the room between them
  std::vector<Vec2> path{to};
  for (int r = reached; previous[static_cast<std::size_t>(r)] >= 0;
       r = previous[static_cast<std::size_t>(r)]) {
    Vec2 c;
    overlap(level_.rooms[static_cast<std::size_t>(r)],
            level_.rooms[static_cast<std::size_t>(previous[static_cast<std::size_t>(r)])], c);
    path.push_back(c);
  }
  std::reverse(path.begin(), path.end());
  return path;
}

int SightedBot::next_case(const GameState& state) const {
  int best = -1;
  double best_length = std::numeric_limits<double>::infinity();
  for (int c = 0; c < state.case_count; ++c) {
    if (state.case_item[static_cast<std::size_t>(c)] < 0) continue;
    const Vec2 pos = level_.cases[static_cast<std::size_t>(c)].pos;
    const std::vector<Vec2> way = route(state.vive.pos, pos);
    if (way.empty()) continue;
    const double l = length(state.vive.pos, way);
    if (l < best_length) {
      best = c;
      best_length = l;
    }
  }
  return best;
}

ViveInput SightedBot::decide(const GameState& state) {
  if (state.phase == Phase::ended || state.paused) return {};
  const ViveState& vive = state.vive;
  const int c = next_case(state);
  const bool deliver = vive.carried_count == kMaxCarried || (vive.carried_count > 0 && c < 0);
  Vec2 goal = level_.table;
  if (deliver) {
    if (distance(vive.pos, level_.table) <= kArrive) return {.deliver = true};
  } else if (c >= 0) {
    goal = level_.cases[static_cast<std::size_t>(c)].pos;
    if (distance(vive.pos, goal) <= kArrive) {
      if (state.case_broken[static_cast<std::size_t>(c)]) return {.take = true};
      // glass is heard far: wait until no guard is within earshot (for a while)
      bool heard = false;
      for (int g = 0; g < state.guard_count; ++g)
        heard = heard || distance(state.guards[static_cast<std::size_t>(g)].pos, goal) <=
                             level_.rules.glass_hear_radius;
      if (waiting_since_tick_ < 0) waiting_since_tick_ = state.tick;
      if (!heard || state.tick - waiting_since_tick_ >= kMaxWaitTicks) {
        waiting_since_tick_ = -1;
        return {.break_case = true};
      }
      // waiting here, unless a guard would catch her: then the look-ahead below moves her away
      if (safe(state, Plan::stand, goal)) return {};
      replan_at_tick_ = state.tick;
    }
  } else if (distance(vive.pos, level_.table) <= kArrive) {
    return {};  // nothing left to fetch: wait by the table
  }
  // every few ticks, look ahead: play the next seconds on a copy of what she sees (the rules
  // are deterministic) going on, standing still, or going back towards the entrance, and take
  // the first way on which no guard catches her
  // (by the state's tick: a client sees a snapshot every few ticks)
  if (state.tick >= replan_at_tick_) {
    replan_at_tick_ = state.tick + kReplanTicks;
    plan_ = Plan::go_on;
    for (const Plan p : {Plan::go_on, Plan::stand, Plan::back_off, Plan::run_on, Plan::run_off}) {
      if (safe(state, p, goal)) {
        plan_ = p;
        break;
      }
    }
  }
  return follow(state.vive.pos, plan_, goal);
}

ViveInput SightedBot::follow(Vec2 from, Plan plan, Vec2 goal) const {
  ViveInput in = step_towards(from, plan == Plan::go_on || plan == Plan::run_on ? goal : level_.entrance,
                              plan == Plan::stand);
  in.run = plan == Plan::run_on || plan == Plan::run_off;
  return in;
}

ViveInput SightedBot::step_towards(Vec2 from, Vec2 goal, bool stand) const {
  if (stand) return {};
  const std::vector<Vec2> way = route(from, goal);
  if (way.empty()) return {};
  Vec2 next = way.front();
  if (distance(from, next) < 0.05 && way.size() > 1) next = way[1];
  // slow down on the last stretch so as to stop where she means to
  const double speed = std::min(1.0, distance(from, next) / (level_.rules.walk_speed * level_.rules.tick_s));
  return {.move = normalized(next - from) * speed};
}

bool SightedBot::safe(const GameState& state, Plan plan, Vec2 goal) const {
  GameState ahead = state;
  ahead.vive.grace_left_s = 0.0;
  Events events;
  for (int t = 0; t < kLookAheadTicks && ahead.phase == Phase::playing; ++t) {
    const ViveInput in = follow(ahead.vive.pos, plan, goal);
    step(level_, ahead, {.vive = in}, events);
    for (int i = 0; i < events.count; ++i)
      if (events.list[static_cast<std::size_t>(i)].type == EventType::vive_caught) return false;
  }
  return true;
}

}  // namespace uh::museum
