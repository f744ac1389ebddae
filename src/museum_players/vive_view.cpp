#include "uh/museum_players/vive_view.hpp"

#include <algorithm>
#include <limits>

namespace uh::museum_players {
namespace {

int kind_index(const museum::Level& level, const std::string& name) {
  for (std::size_t k = 0; k < level.artifact_kinds.size(); ++k)
    if (level.artifact_kinds[k] == name) return static_cast<int>(k);
  return -1;
}

}  // namespace

void ViveView::heard(const museum::Event& event) {
  if (event.guard >= 0 && event.guard < museum::kMaxGuards)
    noise_[static_cast<std::size_t>(event.guard)] = event.pos;
}

const museum::GameState& ViveView::update(const museum_protocol::Snapshot& snapshot,
                                          const std::vector<std::string>& targets) {
  museum::GameState& s = state_;
  s.tick = snapshot.tick;
  s.time_left_s = snapshot.time_left_s;
  s.phase = snapshot.phase == "ended" ? museum::Phase::ended : museum::Phase::playing;
  s.paused = snapshot.phase != "playing";
  s.target_count = static_cast<int>(std::min<std::size_t>(targets.size(), museum::kMaxTargets));
  for (int t = 0; t < s.target_count; ++t)
    s.target_kinds[static_cast<std::size_t>(t)] = kind_index(level_, targets[static_cast<std::size_t>(t)]);
  s.item_count = 2 * s.target_count;
  for (int i = 0; i < s.item_count; ++i) {
    museum::ItemState& item = s.items[static_cast<std::size_t>(i)];
    item.kind = s.target_kinds[static_cast<std::size_t>(i / 2)];
    item.place = museum::ItemPlace::kept;  // judged, unless seen below
  }
  const auto see = [&](const museum_protocol::ItemView& it, museum::ItemPlace place) {
    if (it.item < 0 || it.item >= s.item_count) return -1;
    s.items[static_cast<std::size_t>(it.item)].place = place;
    return it.item;
  };
  s.case_count = static_cast<int>(std::min<std::size_t>(snapshot.cases.size(), museum::kMaxCases));
  for (int c = 0; c < s.case_count; ++c) {
    const museum_protocol::CaseView& seen = snapshot.cases[static_cast<std::size_t>(c)];
    s.case_broken[static_cast<std::size_t>(c)] = seen.broken;
    s.case_item[static_cast<std::size_t>(c)] = -1;
    const int i = see(seen.item, museum::ItemPlace::in_case);
    if (i < 0) continue;
    s.case_item[static_cast<std::size_t>(c)] = i;
    s.items[static_cast<std::size_t>(i)].case_index = c;  // where it goes back when she is caught
  }
  s.vive.pos = snapshot.vive_pos;
  s.vive.facing = snapshot.vive_facing;
  s.vive.running = snapshot.vive_running;
  s.vive.times_caught = snapshot.times_caught;
  s.vive.carried_count = 0;
  for (const museum_protocol::ItemView& it : snapshot.carried) {
    const int i = see(it, museum::ItemPlace::carried);
    if (i >= 0 && s.vive.carried_count < museum::kMaxCarried)
      s.vive.carried[static_cast<std::size_t>(s.vive.carried_count++)] = i;
  }
  s.table_count = 0;
  for (const museum_protocol::ItemView& it : snapshot.table) {
    const int i = see(it, museum::ItemPlace::on_table);
    if (i >= 0 && s.table_count < museum::kMaxItems) s.table[static_cast<std::size_t>(s.table_count++)] = i;
  }
  s.guard_count = static_cast<int>(
      std::min({snapshot.guards.size(), level_.routes.size(), static_cast<std::size_t>(museum::kMaxGuards)}));
  for (int g = 0; g < s.guard_count; ++g) infer_guard(g, snapshot.guards[static_cast<std::size_t>(g)]);
  return s;
}

void ViveView::infer_guard(int g, const museum_protocol::GuardView& seen) {
  museum::GuardState& guard = state_.guards[static_cast<std::size_t>(g)];
  guard.pos = seen.pos;
  guard.facing = seen.facing;
  const std::vector<museum::Vec2>& w = level_.routes[static_cast<std::size_t>(g)].waypoints;
  const int n = static_cast<int>(w.size());
  // the leg of its round nearest to where it stands
  int leg = 0;
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i < n; ++i) {
    const museum::Vec2 a = w[static_cast<std::size_t>(i)], b = w[static_cast<std::size_t>((i + 1) % n)];
    const museum::Vec2 ab = b - a;
    const double len2 = museum::dot(ab, ab);
    const double t = len2 > 0.0 ? std::clamp(museum::dot(guard.pos - a, ab) / len2, 0.0, 1.0) : 0.0;
    const double d = museum::distance(guard.pos, a + ab * t);
    if (d < best) {
      best = d;
      leg = i;
    }
  }
  const std::string& mode = seen.mode;
  const museum::GuardMode was = guard.mode;
  if (mode == "investigate") {
    guard.mode = museum::GuardMode::investigate;
    if (was != museum::GuardMode::investigate) guard.linger_left_s = level_.rules.linger_s;
    guard.noise_pos = noise_[static_cast<std::size_t>(g)];
    guard.goal = museum::clear_path(level_, guard.pos, guard.noise_pos) ? guard.noise_pos : guard.pos;
    guard.trail_count = 0;
  } else if (mode == "returning") {
    guard.mode = museum::GuardMode::returning;
    guard.trail[0] = w[static_cast<std::size_t>(leg)];
    guard.trail_count = 1;
  } else {
    guard.mode = museum::GuardMode::patrol;
    guard.trail_count = 0;
  }
  const museum::Vec2 along = w[static_cast<std::size_t>((leg + 1) % n)] - w[static_cast<std::size_t>(leg)];
  guard.direction = museum::dot(along, guard.facing) >= 0.0 ? 1 : -1;
  guard.next_waypoint = guard.direction > 0 ? (leg + 1) % n : leg;
}

}  // namespace uh::museum_players
