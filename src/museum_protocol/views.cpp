#include "uh/museum_protocol/views.hpp"

namespace uh::museum_protocol {
namespace {

const std::string& kind_name(const museum::Level& level, int kind) {
  return level.artifact_kinds[static_cast<std::size_t>(kind)];
}

ItemView item_view(const museum::Level& level, const museum::GameState& s, int item) {
  return {item, kind_name(level, s.items[static_cast<std::size_t>(item)].kind)};
}

std::vector<std::string> targets_of(const museum::Level& level, const museum::GameState& s) {
  std::vector<std::string> targets;
  for (int t = 0; t < s.target_count; ++t)
    targets.push_back(kind_name(level, s.target_kinds[static_cast<std::size_t>(t)]));
  return targets;
}

}  // namespace

Snapshot snapshot_of(const museum::Level& level, const museum::GameState& s, std::string_view phase,
                     bool vive_connected, bool phantom_connected) {
  Snapshot out{.tick = s.tick,
               .time_left_s = s.time_left_s,
               .phase = std::string(phase),
               .vive_connected = vive_connected,
               .phantom_connected = phantom_connected,
               .targets = targets_of(level, s),
               .vive_pos = s.vive.pos,
               .vive_facing = s.vive.facing,
               .vive_running = s.vive.running,
               .times_caught = s.vive.times_caught};
  for (int i = 0; i < s.vive.carried_count; ++i)
    out.carried.push_back(item_view(level, s, s.vive.carried[static_cast<std::size_t>(i)]));
  for (int g = 0; g < s.guard_count; ++g) {
    const museum::GuardState& guard = s.guards[static_cast<std::size_t>(g)];
    out.guards.push_back({guard.pos, guard.facing, museum::to_string(guard.mode)});
  }
  for (int c = 0; c < s.case_count; ++c) {
    const int item = s.case_item[static_cast<std::size_t>(c)];
    out.cases.push_back(
        {s.case_broken[static_cast<std::size_t>(c)], item >= 0 ? item_view(level, s, item) : ItemView{}});
  }
  for (int i = 0; i < s.table_count; ++i)
    out.table.push_back(item_view(level, s, s.table[static_cast<std::size_t>(i)]));
  out.judged =
      s.score.genuine_kept + s.score.forgeries_kept + s.score.genuine_rejected + s.score.forgeries_rejected;
  return out;
}

Welcome welcome_of(const museum::Level& level, const museum::GameState& state, Role role) {
  Welcome w{.role = to_string(role), .targets = targets_of(level, state)};
  // the welcome tells the level's plan, kinds and told rule numbers; the pieces stay here (each
  // form would tell which piece is which)
  w.level = level;
  w.level.pieces.clear();
  return w;
}

InHand in_hand_of(const museum::Level& level, const museum::GameState& state, int item) {
  const museum::ItemState& it = state.items[static_cast<std::size_t>(item)];
  InHand h{.item = item, .kind = kind_name(level, it.kind)};
  h.form.kind = h.kind;
  h.form.difficulty = level.difficulty;
  if (static_cast<std::size_t>(it.kind) < level.pieces.size()) {
    const museum::PiecePair& pair = level.pieces[static_cast<std::size_t>(it.kind)];
    h.form = it.genuine ? pair.genuine : pair.forgery;
  }
  return h;
}

Summary summary_of(const museum::Level& level, const museum::RoundSummary& s) {
  Summary out{.points = s.score.points,
              .genuine_kept = s.score.genuine_kept,
              .forgeries_kept = s.score.forgeries_kept,
              .genuine_rejected = s.score.genuine_rejected,
              .forgeries_rejected = s.score.forgeries_rejected,
              .time_bonus = s.score.time_bonus,
              .times_caught = s.times_caught,
              .seconds_played = s.seconds_played,
              .ended_early = s.ended_early};
  for (int t = 0; t < s.target_count; ++t) {
    const museum::TargetOutcome& o = s.targets[static_cast<std::size_t>(t)];
    out.targets.push_back(
        {kind_name(level, o.kind), museum::to_string(o.genuine_place), museum::to_string(o.forgery_place)});
  }
  return out;
}

}  // namespace uh::museum_protocol
