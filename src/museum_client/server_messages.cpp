#include "uh/museum_client/server_messages.hpp"

#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "uh/core/json_nesting.hpp"

namespace uh::museum_client {
namespace {

using nlohmann::json;

// Reads fields by path and keeps the first thing wrong; later reads after an error do nothing.
class Reader {
 public:
  std::string error;

  const json* field(const json& j, const char* name, const std::string& path) {
    if (!error.empty()) return nullptr;
    if (!j.is_object()) return fail(path, "must be an object");
    const auto it = j.find(name);
    if (it == j.end()) return fail(path + name, "is missing");
    return &*it;
  }
  double number(const json& j, const char* name, const std::string& path = "") {
    const json* f = field(j, name, path);
    if (f == nullptr) return 0.0;
    if (!f->is_number() || !std::isfinite(f->get<double>()))
      return fail(path + name, "must be a finite number"), 0.0;
    return f->get<double>();
  }
  int integer(const json& j, const char* name, const std::string& path = "") {
    const json* f = field(j, name, path);
    if (f == nullptr) return 0;
    if (!f->is_number_integer() || f->get<std::int64_t>() < std::numeric_limits<int>::min() ||
        f->get<std::int64_t>() > std::numeric_limits<int>::max())
      return fail(path + name, "must be an integer"), 0;
    return static_cast<int>(f->get<std::int64_t>());
  }
  bool boolean(const json& j, const char* name, const std::string& path = "") {
    const json* f = field(j, name, path);
    if (f == nullptr) return false;
    if (!f->is_boolean()) return fail(path + name, "must be true or false"), false;
    return f->get<bool>();
  }
  std::string text(const json& j, const char* name, const std::string& path = "") {
    const json* f = field(j, name, path);
    if (f == nullptr) return {};
    if (!f->is_string()) return fail(path + name, "must be a string"), std::string();
    return f->get<std::string>();
  }
  museum::Vec2 xy(const json& j, const char* name, const std::string& path = "") {
    const json* f = field(j, name, path);
    if (f == nullptr) return {};
    return xy_of(*f, path + name);
  }
  museum::Vec2 xy_of(const json& f, const std::string& path) {
    if (!error.empty()) return {};
    if (!f.is_array() || f.size() != 2 || !f[0].is_number() || !f[1].is_number() ||
        !std::isfinite(f[0].get<double>()) || !std::isfinite(f[1].get<double>()))
      return fail(path, "must be [x, y], two finite numbers"), museum::Vec2{};
    return {f[0].get<double>(), f[1].get<double>()};
  }
  const json* array(const json& j, const char* name, const std::string& path = "") {
    const json* f = field(j, name, path);
    if (f == nullptr) return nullptr;
    if (!f->is_array()) return fail(path + name, "must be an array");
    return f;
  }
  ItemView item(const json& j, const std::string& path) {
    if (j.is_null()) return {};
    return {integer(j, "item", path + "."), text(j, "kind", path + ".")};
  }
  std::vector<ItemView> items(const json& j, const char* name, const std::string& path = "") {
    std::vector<ItemView> out;
    const json* a = array(j, name, path);
    if (a == nullptr) return out;
    for (std::size_t i = 0; i < a->size(); ++i)
      out.push_back(item((*a)[i], fmt::format("{}{}[{}]", path, name, i)));
    return out;
  }

 private:
  const json* fail(const std::string& path, const char* what) {
    if (error.empty()) error = fmt::format("'{}' {}", path, what);
    return nullptr;
  }
};

museum::EventType event_type(const std::string& name, bool& known) {
  known = true;
  for (int t = 0; t <= static_cast<int>(museum::EventType::round_ended); ++t) {
    const auto type = static_cast<museum::EventType>(t);
    if (name == museum::to_string(type)) return type;
  }
  known = false;
  return museum::EventType::round_ended;
}

Result<ServerMessage> parse_welcome(const json& m, Reader& r) {
  Welcome w;
  w.role = r.text(m, "role");
  const json* level = r.field(m, "level", "");
  if (level != nullptr) {
    w.level.name = r.text(*level, "name", "level.");
    const std::string difficulty = r.text(*level, "difficulty", "level.");
    w.level.difficulty = difficulty == "hard" ? museum::Difficulty::hard : museum::Difficulty::easy;
    if (const json* rooms = r.array(*level, "rooms", "level.")) {
      for (std::size_t i = 0; i < rooms->size(); ++i) {
        const std::string path = fmt::format("level.rooms[{}].", i);
        const json& room = (*rooms)[i];
        w.level.rooms.push_back(
            {r.text(room, "name", path), r.xy(room, "min", path), r.xy(room, "max", path)});
      }
    }
    if (const json* cases = r.array(*level, "cases", "level.")) {
      for (std::size_t i = 0; i < cases->size(); ++i)
        w.level.cases.push_back({r.xy_of((*cases)[i], fmt::format("level.cases[{}]", i))});
    }
    w.level.table = r.xy(*level, "table", "level.");
    w.level.entrance = r.xy(*level, "entrance", "level.");
    if (const json* kinds = r.array(*level, "artifact_kinds", "level.")) {
      for (std::size_t i = 0; i < kinds->size() && r.error.empty(); ++i) {
        if (!(*kinds)[i].is_string()) {
          r.error = fmt::format("'level.artifact_kinds[{}]' must be a string", i);
          break;
        }
        w.level.artifact_kinds.push_back((*kinds)[i].get<std::string>());
      }
    }
    if (const json* rules = r.field(*level, "rules", "level.")) {
      w.level.rules.tick_s = r.number(*rules, "tick_s", "level.rules.");
      w.level.rules.round_s = r.number(*rules, "round_s", "level.rules.");
    }
  }
  if (const json* targets = r.array(m, "targets")) {
    for (const json& t : *targets)
      if (t.is_string()) w.targets.push_back(t.get<std::string>());
  }
  if (const auto key = m.find("seat_key"); key != m.end() && key->is_string())
    w.seat_key = key->get<std::string>();
  if (!r.error.empty()) return Error{r.error};
  return ServerMessage{std::move(w)};
}

Result<ServerMessage> parse_snapshot(const json& m, Reader& r) {
  Snapshot s;
  s.tick = r.integer(m, "tick");
  s.time_left_s = r.number(m, "time_left_s");
  s.phase = r.text(m, "phase");
  if (const json* vive = r.field(m, "vive", "")) {
    s.vive_pos = r.xy(*vive, "pos", "vive.");
    s.vive_facing = r.xy(*vive, "facing", "vive.");
    s.vive_running = r.boolean(*vive, "running", "vive.");
    s.times_caught = r.integer(*vive, "times_caught", "vive.");
    if (r.error.empty()) s.carried = r.items(*vive, "carried", "vive.");
  }
  if (const json* guards = r.array(m, "guards")) {
    for (std::size_t i = 0; i < guards->size(); ++i) {
      const std::string path = fmt::format("guards[{}].", i);
      const json& g = (*guards)[i];
      s.guards.push_back({r.xy(g, "pos", path), r.xy(g, "facing", path), r.text(g, "mode", path)});
    }
  }
  if (const json* cases = r.array(m, "cases")) {
    for (std::size_t i = 0; i < cases->size(); ++i) {
      const std::string path = fmt::format("cases[{}].", i);
      CaseView c{.broken = r.boolean((*cases)[i], "broken", path)};
      if (const json* held = r.field((*cases)[i], "item", path)) c.item = r.item(*held, path + "item");
      s.cases.push_back(c);
    }
  }
  s.table = r.items(m, "table");
  s.judged = r.integer(m, "judged");
  if (!r.error.empty()) return Error{r.error};
  return ServerMessage{std::move(s)};
}

Result<ServerMessage> parse_event(const json& m, Reader& r) {
  const std::string name = r.text(m, "event");
  if (!r.error.empty()) return Error{r.error};
  bool known = false;
  museum::Event e{.type = event_type(name, known)};
  if (!known) return Error{fmt::format("'event' is '{}', which this client does not know", name)};
  using museum::EventType;
  switch (e.type) {
    case EventType::case_broken:
      e.case_index = r.integer(m, "case");
      e.pos = r.xy(m, "pos");
      e.radius = r.number(m, "radius");
      break;
    case EventType::case_empty:
      e.case_index = r.integer(m, "case");
      break;
    case EventType::item_taken:
      e.case_index = r.integer(m, "case");
      e.item = r.integer(m, "item");
      break;
    case EventType::items_delivered:
      e.count = r.integer(m, "count");
      break;
    case EventType::guard_heard:
      e.guard = r.integer(m, "guard");
      e.pos = r.xy(m, "pos");
      e.radius = r.number(m, "radius");
      break;
    case EventType::vive_caught:
      e.guard = r.integer(m, "guard");
      e.count = r.integer(m, "items_lost");
      e.pos = r.xy(m, "pos");
      break;
    case EventType::verdict: {
      e.item = r.integer(m, "item");
      const std::string v = r.text(m, "verdict");
      if (r.error.empty() && v != "genuine" && v != "forgery")
        r.error = fmt::format("'verdict' is '{}'; it must be genuine or forgery", v);
      e.verdict = v == "genuine" ? museum::Verdict::genuine : museum::Verdict::forgery;
      break;
    }
    case EventType::time_warning:
      e.count = r.integer(m, "seconds_left");
      break;
    case EventType::round_ended:
      break;
  }
  if (!r.error.empty()) return Error{r.error};
  return ServerMessage{GameEvent{e}};
}

Result<ServerMessage> parse_in_hand(const json& m, Reader& r) {
  InHand h;
  const json* item = r.field(m, "item", "");
  if (item != nullptr && !item->is_null()) {
    h.item = r.integer(m, "item");
    h.kind = r.text(m, "kind");
    const std::string piece = r.text(m, "piece");
    if (r.error.empty() && piece != "genuine" && piece != "forgery")
      r.error = fmt::format("'piece' is '{}'; it must be genuine or forgery", piece);
    h.piece = piece == "forgery" ? museum::Piece::forgery : museum::Piece::genuine;
  }
  if (!r.error.empty()) return Error{r.error};
  return ServerMessage{h};
}

Result<ServerMessage> parse_summary(const json& m, Reader& r) {
  Summary s;
  if (const json* score = r.field(m, "score", "")) {
    s.points = r.integer(*score, "points", "score.");
    s.genuine_kept = r.integer(*score, "genuine_kept", "score.");
    s.forgeries_kept = r.integer(*score, "forgeries_kept", "score.");
    s.genuine_rejected = r.integer(*score, "genuine_rejected", "score.");
    s.forgeries_rejected = r.integer(*score, "forgeries_rejected", "score.");
    s.time_bonus = r.integer(*score, "time_bonus", "score.");
  }
  if (const json* targets = r.array(m, "targets")) {
    for (std::size_t i = 0; i < targets->size(); ++i) {
      const std::string path = fmt::format("targets[{}].", i);
      const json& t = (*targets)[i];
      s.targets.push_back({r.text(t, "kind", path), r.text(t, "genuine", path), r.text(t, "forgery", path)});
    }
  }
  s.times_caught = r.integer(m, "times_caught");
  s.seconds_played = r.number(m, "seconds_played");
  s.ended_early = r.boolean(m, "ended_early");
  if (!r.error.empty()) return Error{r.error};
  return ServerMessage{s};
}

}  // namespace

Result<ServerMessage> parse_server_message(std::string_view text) {
  if (json_nesting_depth(text) > kMaxJsonNesting)
    return Error{fmt::format("the message is nested deeper than {} levels", kMaxJsonNesting)};
  const json m = json::parse(text, nullptr, false);
  if (m.is_discarded()) return Error{"the message is not JSON"};
  if (!m.is_object()) return Error{"the message is not a JSON object"};
  Reader r;
  const std::string type = r.text(m, "type");
  if (!r.error.empty()) return Error{r.error};
  if (type == "welcome") return parse_welcome(m, r);
  if (type == "snapshot") return parse_snapshot(m, r);
  if (type == "event") return parse_event(m, r);
  if (type == "in_hands") return parse_in_hand(m, r);
  if (type == "summary") return parse_summary(m, r);
  if (type == "error") {
    ServerError e;
    if (const auto it = m.find("request"); it != m.end() && it->is_string())
      e.request = it->get<std::string>();
    e.message = r.text(m, "message");
    if (!r.error.empty()) return Error{r.error};
    return ServerMessage{e};
  }
  if (type == "pong") return ServerMessage{Ignored{type}};
  return Error{fmt::format("'type' is '{}', which this client does not know", type)};
}

std::string hello_text(std::string_view role, std::string_view token, std::string_view seat_key) {
  json hello = {{"type", "hello"}, {"protocol", 1}, {"role", std::string(role)}};
  if (!token.empty()) hello["token"] = std::string(token);
  if (!seat_key.empty()) hello["seat_key"] = std::string(seat_key);
  return hello.dump();
}

std::string verdict_text(int item, museum::Verdict verdict) {
  return json{{"type", "verdict"}, {"item", item}, {"verdict", museum::to_string(verdict)}}.dump();
}

std::string move_text(museum::Vec2 move, bool run) {
  return json{{"type", "move"}, {"move", {move.x, move.y}}, {"run", run}}.dump();
}

std::string action_text(std::string_view action) {
  return json{{"type", "action"}, {"action", std::string(action)}}.dump();
}

}  // namespace uh::museum_client
