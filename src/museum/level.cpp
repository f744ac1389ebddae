#include "uh/museum/level.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace uh::museum {

const char* to_string(Difficulty difficulty) {
  switch (difficulty) {
    case Difficulty::easy:
      return "easy";
    case Difficulty::hard:
      return "hard";
  }
  return "unknown";
}

namespace {

// the artifact set (docs/museum.md): each kind comes as a genuine piece and a forgery
const std::vector<std::string> kArtifactKinds = {"amphora", "bowl", "coin", "tablet", "scarab", "goblet"};

// a square loop of waypoints around a rectangle, walked counter-clockwise by default
PatrolRoute loop(Vec2 lo, Vec2 hi) { return {{{lo.x, lo.y}, {hi.x, lo.y}, {hi.x, hi.y}, {lo.x, hi.y}}}; }

}  // namespace

Level make_level(Difficulty difficulty) {
  Level level;
  level.difficulty = difficulty;
  level.name = fmt::format("the collector's museum ({})", to_string(difficulty));
  // the dock (Phantom's van) west, the great hall, a gallery east and one north; walls 1 m thick,
  // doorways overlap the rooms they join
  level.rooms = {
      {"loading dock", {0.0, 0.0}, {6.0, 6.0}},    {"dock door", {5.5, 2.5}, {7.5, 3.5}},
      {"great hall", {7.0, 0.0}, {19.0, 8.0}},     {"east arch", {18.5, 5.0}, {20.5, 6.5}},
      {"east gallery", {20.0, 0.0}, {28.0, 8.0}},  {"north arch", {12.0, 7.5}, {13.5, 9.5}},
      {"north gallery", {8.0, 9.0}, {19.0, 15.0}},
  };
  level.entrance = {1.0, 3.0};
  level.table = {4.0, 3.0};
  level.cases = {{{9.0, 6.5}},  {{12.0, 1.5}}, {{16.0, 6.5}},  {{22.0, 1.5}},
                 {{26.0, 6.5}}, {{26.0, 1.5}}, {{10.0, 13.5}}, {{17.0, 13.5}}};
  level.routes = {loop({9.0, 3.5}, {17.5, 5.5}), loop({9.5, 11.0}, {17.5, 12.5})};
  level.artifact_kinds = kArtifactKinds;
  if (difficulty == Difficulty::hard) {
    // a vault north of the east gallery, four more cases and two more guards with sharper senses
    level.rooms.push_back({"vault door", {23.0, 7.5}, {24.0, 9.5}});
    level.rooms.push_back({"vault", {20.0, 9.0}, {28.0, 15.0}});
    level.cases.push_back({{13.5, 10.2}});
    level.cases.push_back({{22.0, 13.5}});
    level.cases.push_back({{26.0, 13.5}});
    level.cases.push_back({{27.0, 10.0}});
    level.routes.push_back(loop({21.0, 2.5}, {27.0, 4.0}));
    level.routes.push_back(loop({21.0, 11.0}, {27.0, 12.2}));
    level.target_count = 4;
    RuleNumbers& r = level.rules;
    r.round_s = 300.0;
    r.run_hear_radius = 6.0;
    r.glass_hear_radius = 12.0;
    r.view_range = 7.0;
    r.view_half_angle_deg = 40.0;
    r.patrol_speed = 1.2;
    r.investigate_speed = 2.2;
    r.linger_s = 6.0;
    r.caught_penalty_s = 30.0;
  }
  return level;
}

bool walkable(const Level& level, Vec2 p) {
  return std::any_of(level.rooms.begin(), level.rooms.end(), [&](const Room& room) {
    return p.x >= room.min.x && p.x <= room.max.x && p.y >= room.min.y && p.y <= room.max.y;
  });
}

bool clear_path(const Level& level, Vec2 a, Vec2 b) {
  constexpr double kSampleStep = 0.02;  // [m]
  const int samples = static_cast<int>(std::ceil(distance(a, b) / kSampleStep));
  for (int i = 0; i <= samples; ++i) {
    const double t = samples == 0 ? 0.0 : static_cast<double>(i) / samples;
    if (!walkable(level, a + (b - a) * t)) return false;
  }
  return true;
}

namespace {

bool finite(Vec2 p) { return std::isfinite(p.x) && std::isfinite(p.y); }

std::string where(Vec2 p) { return fmt::format("({:g}, {:g})", p.x, p.y); }

}  // namespace

Status validate(const Level& level) {
  const std::string& name = level.name;
  if (level.rooms.empty()) return Error{fmt::format("{}: no rooms", name)};
  for (const Room& room : level.rooms) {
    if (!finite(room.min) || !finite(room.max) || !(room.min.x < room.max.x) || !(room.min.y < room.max.y)) {
      return Error{fmt::format("{}: room '{}' is not a rectangle (min {} must be below and left of max {})",
                               name, room.name, where(room.min), where(room.max))};
    }
  }
  if (level.cases.size() > static_cast<std::size_t>(kMaxCases)) {
    return Error{fmt::format("{}: {} cases, at most {} supported", name, level.cases.size(), kMaxCases)};
  }
  if (level.routes.size() > static_cast<std::size_t>(kMaxGuards)) {
    return Error{fmt::format("{}: {} patrol routes, at most {} guards supported", name, level.routes.size(),
                             kMaxGuards)};
  }
  if (level.artifact_kinds.size() > static_cast<std::size_t>(kMaxArtifactKinds)) {
    return Error{fmt::format("{}: {} artifact kinds, at most {} supported", name, level.artifact_kinds.size(),
                             kMaxArtifactKinds)};
  }
  if (level.target_count < 1 || level.target_count > kMaxTargets) {
    return Error{
        fmt::format("{}: target_count {} is not within 1..{}", name, level.target_count, kMaxTargets)};
  }
  if (static_cast<std::size_t>(level.target_count) > level.artifact_kinds.size()) {
    return Error{fmt::format("{}: {} targets but only {} artifact kinds", name, level.target_count,
                             level.artifact_kinds.size())};
  }
  if (level.cases.size() < static_cast<std::size_t>(2 * level.target_count)) {
    return Error{fmt::format("{}: {} cases cannot hold a genuine piece and a forgery for each of {} targets",
                             name, level.cases.size(), level.target_count)};
  }
  if (!walkable(level, level.entrance))
    return Error{fmt::format("{}: the entrance {} is not on the floor", name, where(level.entrance))};
  if (!walkable(level, level.table))
    return Error{fmt::format("{}: Phantom's table {} is not on the floor", name, where(level.table))};
  for (std::size_t c = 0; c < level.cases.size(); ++c) {
    if (!walkable(level, level.cases[c].pos)) {
      return Error{fmt::format("{}: case {} at {} is not on the floor", name, c, where(level.cases[c].pos))};
    }
  }
  for (std::size_t g = 0; g < level.routes.size(); ++g) {
    const std::vector<Vec2>& w = level.routes[g].waypoints;
    if (w.size() < 2)
      return Error{fmt::format("{}: patrol route {} has {} waypoints, at least 2 needed", name, g, w.size())};
    for (std::size_t i = 0; i < w.size(); ++i) {
      const Vec2 a = w[i];
      const Vec2 b = w[(i + 1) % w.size()];
      if (!walkable(level, a))
        return Error{
            fmt::format("{}: patrol route {} waypoint {} at {} is not on the floor", name, g, i, where(a))};
      if (!clear_path(level, a, b)) {
        return Error{fmt::format("{}: patrol route {} goes through a wall from {} to {}", name, g, where(a),
                                 where(b))};
      }
    }
  }
  const RuleNumbers& r = level.rules;
  for (const RuleField& f : kRuleFields) {
    const double value = r.*f.value;
    if (f.positive && (!(value > 0.0) || !std::isfinite(value)))
      return Error{fmt::format("{}: rules.{} is {}, must be positive", name, f.name, value)};
    if (!f.positive && (!(value >= 0.0) || !std::isfinite(value)))
      return Error{fmt::format("{}: rules.{} is {}, must be 0 or more", name, f.name, value)};
  }
  if (!level.pieces.empty() && level.pieces.size() != level.artifact_kinds.size())
    return Error{fmt::format("{}: {} piece pairs for {} artifact kinds", name, level.pieces.size(),
                             level.artifact_kinds.size())};
  for (std::size_t k = 0; k < level.pieces.size(); ++k) {
    for (const PieceForm* form : {&level.pieces[k].genuine, &level.pieces[k].forgery}) {
      if (form->kind != level.artifact_kinds[k] || form->difficulty != level.difficulty)
        return Error{fmt::format("{}: the pieces of kind {} are {} ({}), not {} ({})", name, k, form->kind,
                                 to_string(form->difficulty), level.artifact_kinds[k],
                                 to_string(level.difficulty))};
    }
  }
  if (r.view_half_angle_deg > 180.0)
    return Error{fmt::format("{}: rules.view_half_angle_deg {} is over 180", name, r.view_half_angle_deg)};
  return Ok{};
}

}  // namespace uh::museum
