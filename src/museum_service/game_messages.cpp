#include "game_messages.hpp"

#include <cmath>

#include <fmt/format.h>

#include "uh/core/json_nesting.hpp"
#include "uh/museum_service/game_server.hpp"

namespace uh::museum_service {

const char* to_string(Role role) {
  switch (role) {
    case Role::none:
      return "none";
    case Role::vive:
      return "vive";
    case Role::phantom:
      return "phantom";
    case Role::watcher:
      return "watcher";
  }
  return "unknown";
}

namespace {

using museum::Vec2;

json xy(Vec2 v) { return json::array({v.x, v.y}); }

// each returns an error text, or empty when the field was read (or is absent and optional)
std::string read_bool(const json& m, const char* field, bool& out) {
  const auto it = m.find(field);
  if (it == m.end()) return {};
  if (!it->is_boolean()) return fmt::format("'{}' must be true or false", field);
  out = it->get<bool>();
  return {};
}

std::string read_choice(const json& m, const char* field, std::string& out) {
  const auto it = m.find(field);
  if (it == m.end()) return fmt::format("'{}' is missing", field);
  if (!it->is_string()) return fmt::format("'{}' must be a string", field);
  out = it->get<std::string>();
  return {};
}

std::string parse_body(const json& m, const std::string& type, std::optional<ClientMessage>& body) {
  std::string e;
  if (type == "hello") {
    HelloMessage h;
    const auto p = m.find("protocol");
    if (p == m.end() || !p->is_number_integer())
      return "'protocol' must be an integer (this server speaks 1)";
    h.protocol = static_cast<int>(std::clamp<std::int64_t>(p->get<std::int64_t>(), -1000000, 1000000));
    std::string role;
    if (e = read_choice(m, "role", role); !e.empty()) return e + " (vive, phantom or watcher)";
    if (role == "vive")
      h.role = Role::vive;
    else if (role == "phantom")
      h.role = Role::phantom;
    else if (role == "watcher")
      h.role = Role::watcher;
    else
      return fmt::format("'role' is '{}'; it must be vive, phantom or watcher", role);
    if (const auto t = m.find("token"); t != m.end()) {
      if (!t->is_string()) return "'token' must be a string";
      h.token = t->get<std::string>();
    }
    if (const auto k = m.find("seat_key"); k != m.end()) {
      if (!k->is_string()) return "'seat_key' must be a string";
      h.seat_key = k->get<std::string>();
    }
    body = h;
  } else if (type == "move") {
    MoveMessage mv;
    const auto d = m.find("move");
    if (d == m.end() || !d->is_array() || d->size() != 2 || !(*d)[0].is_number() || !(*d)[1].is_number())
      return "'move' must be [x, y], a direction on the floor";
    mv.move = {(*d)[0].get<double>(), (*d)[1].get<double>()};
    if (!std::isfinite(mv.move.x) || !std::isfinite(mv.move.y)) return "'move' must be finite";
    if (e = read_bool(m, "run", mv.run); !e.empty()) return e;
    body = mv;
  } else if (type == "action") {
    std::string a;
    if (e = read_choice(m, "action", a); !e.empty()) return e + " (break, take or deliver)";
    if (a == "break")
      body = ActionMessage{Action::break_case};
    else if (a == "take")
      body = ActionMessage{Action::take};
    else if (a == "deliver")
      body = ActionMessage{Action::deliver};
    else
      return fmt::format("'action' is '{}'; it must be break, take or deliver", a);
  } else if (type == "verdict") {
    VerdictMessage vm;
    const auto item = m.find("item");
    if (item == m.end() || !item->is_number_integer() || item->get<std::int64_t>() < 0 ||
        item->get<std::int64_t>() >= museum::kMaxItems)
      return "'item' must be the number of the artifact on the table (as in the snapshot's table)";
    vm.item = static_cast<int>(item->get<std::int64_t>());
    std::string v;
    if (e = read_choice(m, "verdict", v); !e.empty()) return e + " (genuine or forgery)";
    if (v == "genuine")
      vm.verdict = museum::Verdict::genuine;
    else if (v == "forgery")
      vm.verdict = museum::Verdict::forgery;
    else
      return fmt::format("'verdict' is '{}'; it must be genuine or forgery", v);
    body = vm;
  } else if (type == "ping") {
    body = PingMessage{};
  } else {
    return fmt::format("unknown message type '{}' (hello, move, action, verdict or ping)", type);
  }
  return {};
}

}  // namespace

ParsedMessage parse_message(std::string_view text) {
  ParsedMessage out;
  if (json_nesting_depth(text) > kMaxJsonNesting) {
    out.error = fmt::format("the message is nested deeper than {} levels", kMaxJsonNesting);
    return out;
  }
  const json m = json::parse(text, nullptr, false);
  if (m.is_discarded()) {
    out.error = "the message is not JSON";
    return out;
  }
  if (!m.is_object()) {
    out.error = "the message must be a JSON object with a 'type'";
    return out;
  }
  if (const auto id = m.find("id"); id != m.end()) out.id = *id;
  const auto type = m.find("type");
  if (type == m.end() || !type->is_string()) {
    out.error = "'type' is missing or not a string";
    return out;
  }
  out.type = type->get<std::string>();
  out.error = parse_body(m, out.type, out.body);
  if (!out.error.empty()) out.body.reset();
  return out;
}

json error_message(const json& id, std::string_view request_type, std::string_view message) {
  return {{"type", "error"}, {"id", id}, {"request", request_type}, {"message", message}};
}

json level_json(const museum::Level& level) {
  json rooms = json::array();
  for (const museum::Room& r : level.rooms)
    rooms.push_back({{"name", r.name}, {"min", xy(r.min)}, {"max", xy(r.max)}});
  json cases = json::array();
  for (const museum::DisplayCase& c : level.cases) cases.push_back(xy(c.pos));
  const museum::RuleNumbers& r = level.rules;
  return {{"name", level.name},
          {"difficulty", museum::to_string(level.difficulty)},
          {"rooms", rooms},
          {"cases", cases},
          {"table", xy(level.table)},
          {"entrance", xy(level.entrance)},
          {"artifact_kinds", level.artifact_kinds},
          {"rules",
           {{"tick_s", r.tick_s},
            {"round_s", r.round_s},
            {"walk_speed", r.walk_speed},
            {"run_speed", r.run_speed},
            {"reach", r.reach},
            {"run_hear_radius", r.run_hear_radius},
            {"glass_hear_radius", r.glass_hear_radius},
            {"view_range", r.view_range},
            {"view_half_angle_deg", r.view_half_angle_deg},
            {"max_carried", museum::kMaxCarried}}}};
}

namespace {

json item_json(const museum::Level& level, const museum::GameState& s, int item) {
  const int kind = s.items[static_cast<std::size_t>(item)].kind;
  return {{"item", item}, {"kind", level.artifact_kinds[static_cast<std::size_t>(kind)]}};
}

}  // namespace

json snapshot_json(const museum::Level& level, const museum::GameState& s, std::string_view phase,
                   bool vive_connected, bool phantom_connected) {
  json carried = json::array();
  for (int i = 0; i < s.vive.carried_count; ++i)
    carried.push_back(item_json(level, s, s.vive.carried[static_cast<std::size_t>(i)]));
  json guards = json::array();
  for (int g = 0; g < s.guard_count; ++g) {
    const museum::GuardState& guard = s.guards[static_cast<std::size_t>(g)];
    guards.push_back(
        {{"pos", xy(guard.pos)}, {"facing", xy(guard.facing)}, {"mode", museum::to_string(guard.mode)}});
  }
  json cases = json::array();
  for (int c = 0; c < s.case_count; ++c) {
    const int item = s.case_item[static_cast<std::size_t>(c)];
    cases.push_back({{"broken", s.case_broken[static_cast<std::size_t>(c)]},
                     {"item", item >= 0 ? item_json(level, s, item) : json(nullptr)}});
  }
  json table = json::array();
  for (int i = 0; i < s.table_count; ++i)
    table.push_back(item_json(level, s, s.table[static_cast<std::size_t>(i)]));
  json targets = json::array();
  for (int t = 0; t < s.target_count; ++t)
    targets.push_back(
        level.artifact_kinds[static_cast<std::size_t>(s.target_kinds[static_cast<std::size_t>(t)])]);
  return {{"type", "snapshot"},
          {"tick", s.tick},
          {"time_left_s", s.time_left_s},
          {"phase", phase},
          {"players", {{"vive", vive_connected}, {"phantom", phantom_connected}}},
          {"targets", targets},
          {"vive",
           {{"pos", xy(s.vive.pos)},
            {"facing", xy(s.vive.facing)},
            {"running", s.vive.running},
            {"carried", carried},
            {"times_caught", s.vive.times_caught}}},
          {"guards", guards},
          {"cases", cases},
          {"table", table},
          {"judged", s.score.genuine_kept + s.score.forgeries_kept + s.score.genuine_rejected +
                         s.score.forgeries_rejected}};
}

json event_json(const museum::Event& e) {
  using museum::EventType;
  json j = {{"type", "event"}, {"event", museum::to_string(e.type)}};
  switch (e.type) {
    case EventType::case_broken:
      j["case"] = e.case_index;
      j["pos"] = xy(e.pos);
      j["radius"] = e.radius;
      break;
    case EventType::case_empty:
      j["case"] = e.case_index;
      break;
    case EventType::item_taken:
      j["case"] = e.case_index;
      j["item"] = e.item;
      break;
    case EventType::items_delivered:
      j["count"] = e.count;
      break;
    case EventType::guard_heard:
      j["guard"] = e.guard;
      j["pos"] = xy(e.pos);
      j["radius"] = e.radius;
      break;
    case EventType::vive_caught:
      j["guard"] = e.guard;
      j["items_lost"] = e.count;
      j["pos"] = xy(e.pos);
      break;
    case EventType::verdict:
      // whether it was right is told in the summary only
      j["item"] = e.item;
      j["verdict"] = museum::to_string(e.verdict);
      break;
    case EventType::time_warning:
      j["seconds_left"] = e.count;
      break;
    case EventType::round_ended:
      break;
  }
  return j;
}

json in_hands_json(const museum::Level& level, const museum::GameState& state, int item) {
  const museum::ItemState& it = state.items[static_cast<std::size_t>(item)];
  return {{"type", "in_hands"},
          {"item", item},
          {"kind", level.artifact_kinds[static_cast<std::size_t>(it.kind)]},
          {"piece", it.genuine ? "genuine" : "forgery"}};
}

json summary_json(const museum::Level& level, const museum::RoundSummary& s) {
  json targets = json::array();
  for (int t = 0; t < s.target_count; ++t) {
    const museum::TargetOutcome& o = s.targets[static_cast<std::size_t>(t)];
    targets.push_back({{"kind", level.artifact_kinds[static_cast<std::size_t>(o.kind)]},
                       {"genuine", museum::to_string(o.genuine_place)},
                       {"forgery", museum::to_string(o.forgery_place)}});
  }
  return {{"type", "summary"},
          {"targets", targets},
          {"score",
           {{"points", s.score.points},
            {"genuine_kept", s.score.genuine_kept},
            {"forgeries_kept", s.score.forgeries_kept},
            {"genuine_rejected", s.score.genuine_rejected},
            {"forgeries_rejected", s.score.forgeries_rejected},
            {"time_bonus", s.score.time_bonus}}},
          {"times_caught", s.times_caught},
          {"seconds_played", s.seconds_played},
          {"ended_early", s.ended_early}};
}

}  // namespace uh::museum_service
