#include "uh/museum_protocol/messages.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "uh/core/json_fields.hpp"

namespace uh::museum_protocol {

using nlohmann::json;

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

std::optional<Role> role_named(std::string_view name) {
  for (const Role r : {Role::vive, Role::phantom, Role::watcher})
    if (name == to_string(r)) return r;
  return std::nullopt;
}

const char* to_string(Action action) {
  switch (action) {
    case Action::break_case:
      return "break";
    case Action::take:
      return "take";
    case Action::deliver:
      return "deliver";
  }
  return "unknown";
}

namespace {

json xy(museum::Vec2 v) { return json::array({v.x, v.y}); }

// a message's text; what a client sent (an id, a type, the parser's words on its text) may hold
// bytes that are not UTF-8: they are written replaced, never thrown on
std::string text(const json& message) { return message.dump(-1, ' ', false, json::error_handler_t::replace); }

// the document behind the nesting guard, or why there is none
Result<json> read_object(std::string_view text) {
  auto document = parse_json_document(text);
  if (!document) return Error{"the message: " + document.error().message};
  return document;
}

// ---- client to server

// each returns an error text, or empty when the body was read
std::string read_hello(const json& m, JsonFields& f, std::optional<ClientMessage>& body) {
  HelloMessage h;
  const json* p = f.optional(m, "protocol");
  if (p == nullptr || !p->is_number_integer()) return "'protocol' must be an integer (this server speaks 1)";
  h.protocol = static_cast<int>(std::clamp<std::int64_t>(p->get<std::int64_t>(), -1000000, 1000000));
  const std::string role = f.text(m, "role");
  if (!f.ok()) return f.error() + " (vive, phantom or watcher)";
  const auto named = role_named(role);
  if (!named) return fmt::format("'role' is '{}'; it must be vive, phantom or watcher", role);
  h.role = *named;
  if (f.optional(m, "token") != nullptr) h.token = f.text(m, "token");
  if (f.optional(m, "seat_key") != nullptr) h.seat_key = f.text(m, "seat_key");
  if (!f.ok()) return f.error();
  body = h;
  return {};
}

std::string read_move(const json& m, JsonFields& f, std::optional<ClientMessage>& body) {
  MoveMessage mv;
  const json* d = f.optional(m, "move");
  if (d == nullptr || !d->is_array() || d->size() != 2 || !(*d)[0].is_number() || !(*d)[1].is_number())
    return "'move' must be [x, y], a direction on the floor";
  mv.move = {(*d)[0].get<double>(), (*d)[1].get<double>()};
  if (!std::isfinite(mv.move.x) || !std::isfinite(mv.move.y)) return "'move' must be finite";
  if (f.optional(m, "run") != nullptr) mv.run = f.boolean(m, "run");
  if (!f.ok()) return f.error();
  body = mv;
  return {};
}

std::string read_action(const json& m, JsonFields& f, std::optional<ClientMessage>& body) {
  const std::string a = f.text(m, "action");
  if (!f.ok()) return f.error() + " (break, take or deliver)";
  for (const Action action : {Action::break_case, Action::take, Action::deliver}) {
    if (a == to_string(action)) {
      body = ActionMessage{action};
      return {};
    }
  }
  return fmt::format("'action' is '{}'; it must be break, take or deliver", a);
}

std::string read_verdict(const json& m, JsonFields& f, std::optional<ClientMessage>& body) {
  VerdictMessage vm;
  const json* item = f.optional(m, "item");
  if (item == nullptr || !item->is_number_integer() || item->get<std::int64_t>() < 0 ||
      item->get<std::int64_t>() >= museum::kMaxItems)
    return "'item' must be the number of the artifact on the table (as in the snapshot's table)";
  vm.item = static_cast<int>(item->get<std::int64_t>());
  const std::string v = f.text(m, "verdict");
  if (!f.ok()) return f.error() + " (genuine or forgery)";
  if (v == "genuine")
    vm.verdict = museum::Verdict::genuine;
  else if (v == "forgery")
    vm.verdict = museum::Verdict::forgery;
  else
    return fmt::format("'verdict' is '{}'; it must be genuine or forgery", v);
  body = vm;
  return {};
}

std::string read_client_body(const json& m, const std::string& type, std::optional<ClientMessage>& body) {
  JsonFields f;
  if (type == "hello") return read_hello(m, f, body);
  if (type == "move") return read_move(m, f, body);
  if (type == "action") return read_action(m, f, body);
  if (type == "verdict") return read_verdict(m, f, body);
  if (type == "ping") {
    body = PingMessage{};
    return {};
  }
  return fmt::format("unknown message type '{}' (hello, move, action, verdict or ping)", type);
}

}  // namespace

ParsedClientMessage read_client_message(std::string_view text) {
  ParsedClientMessage out;
  auto document = read_object(text);
  if (!document) {
    out.error = document.error().message;
    return out;
  }
  const json& m = *document;
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
  out.error = read_client_body(m, out.type, out.body);
  if (!out.error.empty()) out.body.reset();
  return out;
}

std::string write_message(const HelloMessage& m) {
  json hello = {{"type", "hello"}, {"protocol", m.protocol}, {"role", to_string(m.role)}};
  if (!m.token.empty()) hello["token"] = m.token;
  if (!m.seat_key.empty()) hello["seat_key"] = m.seat_key;
  return text(hello);
}

std::string write_message(const MoveMessage& m) {
  return text(json{{"type", "move"}, {"move", xy(m.move)}, {"run", m.run}});
}

std::string write_message(const ActionMessage& m) {
  return text(json{{"type", "action"}, {"action", to_string(m.action)}});
}

std::string write_message(const VerdictMessage& m) {
  return text(json{{"type", "verdict"}, {"item", m.item}, {"verdict", museum::to_string(m.verdict)}});
}

// ---- server to client

namespace {

json id_of(const json& m) {
  const auto it = m.find("id");
  return it == m.end() ? json(nullptr) : *it;
}

museum::Vec2 read_xy(JsonFields& f, const json& value, const std::string& path) {
  if (!f.ok()) return {};
  if (!value.is_array() || value.size() != 2)
    return f.fail(path, "must be [x, y], two finite numbers"), museum::Vec2{};
  const double x = f.number_of(value[0], path + "[0]"), y = f.number_of(value[1], path + "[1]");
  return {x, y};
}

museum::Vec2 field_xy(JsonFields& f, const json& object, const char* name, const std::string& path = "") {
  const json* v = f.field(object, name, path);
  return v == nullptr ? museum::Vec2{} : read_xy(f, *v, path + name);
}

ItemView read_item(JsonFields& f, const json& value, const std::string& path) {
  if (value.is_null()) return {};
  return {f.integer(value, "item", path + "."), f.text(value, "kind", path + ".")};
}

std::vector<ItemView> read_items(JsonFields& f, const json& object, const char* name,
                                 const std::string& path = "") {
  std::vector<ItemView> out;
  if (const json* a = f.array(object, name, path))
    for (std::size_t i = 0; i < a->size() && f.ok(); ++i)
      out.push_back(read_item(f, (*a)[i], fmt::format("{}{}[{}]", path, name, i)));
  return out;
}

std::vector<std::string> read_texts(JsonFields& f, const json& object, const char* name,
                                    const std::string& path = "") {
  std::vector<std::string> out;
  if (const json* a = f.array(object, name, path))
    for (std::size_t i = 0; i < a->size() && f.ok(); ++i)
      out.push_back(f.text_of((*a)[i], fmt::format("{}{}[{}]", path, name, i)));
  return out;
}

museum::Difficulty read_difficulty(JsonFields& f, const json& object, const std::string& path) {
  const std::string d = f.text(object, "difficulty", path);
  if (f.ok() && d != "easy" && d != "hard") f.fail(path + "difficulty", "must be easy or hard");
  return d == "hard" ? museum::Difficulty::hard : museum::Difficulty::easy;
}

json level_json(const museum::Level& level) {
  json rooms = json::array();
  for (const museum::Room& r : level.rooms)
    rooms.push_back({{"name", r.name}, {"min", xy(r.min)}, {"max", xy(r.max)}});
  json cases = json::array();
  for (const museum::DisplayCase& c : level.cases) cases.push_back(xy(c.pos));
  json rules = {{"max_carried", museum::kMaxCarried}};
  for (const museum::RuleField& r : museum::kRuleFields)
    if (r.told) rules[r.name] = level.rules.*r.value;
  return {{"name", level.name},
          {"difficulty", museum::to_string(level.difficulty)},
          {"rooms", rooms},
          {"cases", cases},
          {"table", xy(level.table)},
          {"entrance", xy(level.entrance)},
          {"artifact_kinds", level.artifact_kinds},
          {"rules", rules}};
}

void read_level(JsonFields& f, const json& level, museum::Level& out) {
  out.name = f.text(level, "name", "level.");
  out.difficulty = read_difficulty(f, level, "level.");
  if (const json* rooms = f.array(level, "rooms", "level.")) {
    for (std::size_t i = 0; i < rooms->size() && f.ok(); ++i) {
      const std::string path = fmt::format("level.rooms[{}].", i);
      const json& room = (*rooms)[i];
      out.rooms.push_back(
          {f.text(room, "name", path), field_xy(f, room, "min", path), field_xy(f, room, "max", path)});
    }
  }
  if (const json* cases = f.array(level, "cases", "level."))
    for (std::size_t i = 0; i < cases->size() && f.ok(); ++i)
      out.cases.push_back({read_xy(f, (*cases)[i], fmt::format("level.cases[{}]", i))});
  out.table = field_xy(f, level, "table", "level.");
  out.entrance = field_xy(f, level, "entrance", "level.");
  out.artifact_kinds = read_texts(f, level, "artifact_kinds", "level.");
  if (const json* rules = f.field(level, "rules", "level."))
    for (const museum::RuleField& r : museum::kRuleFields)
      if (r.told) out.rules.*r.value = f.number(*rules, r.name, "level.rules.");
}

Result<ServerMessage> read_welcome(const json& m, JsonFields& f) {
  Welcome w{.id = id_of(m)};
  w.protocol = f.integer(m, "protocol");
  w.role = f.text(m, "role");
  if (const json* level = f.field(m, "level")) read_level(f, *level, w.level);
  w.targets = read_texts(f, m, "targets");
  if (f.optional(m, "seat_key") != nullptr) w.seat_key = f.text(m, "seat_key");
  if (!f.ok()) return Error{f.error()};
  return ServerMessage{std::move(w)};
}

Result<ServerMessage> read_snapshot(const json& m, JsonFields& f) {
  Snapshot s;
  s.tick = f.integer(m, "tick");
  s.time_left_s = f.number(m, "time_left_s");
  s.phase = f.text(m, "phase");
  if (const json* vive = f.field(m, "vive")) {
    s.vive_pos = field_xy(f, *vive, "pos", "vive.");
    s.vive_facing = field_xy(f, *vive, "facing", "vive.");
    s.vive_running = f.boolean(*vive, "running", "vive.");
    s.times_caught = f.integer(*vive, "times_caught", "vive.");
    s.carried = read_items(f, *vive, "carried", "vive.");
  }
  if (const json* guards = f.array(m, "guards")) {
    for (std::size_t i = 0; i < guards->size() && f.ok(); ++i) {
      const std::string path = fmt::format("guards[{}].", i);
      const json& g = (*guards)[i];
      s.guards.push_back(
          {field_xy(f, g, "pos", path), field_xy(f, g, "facing", path), f.text(g, "mode", path)});
    }
  }
  if (const json* cases = f.array(m, "cases")) {
    for (std::size_t i = 0; i < cases->size() && f.ok(); ++i) {
      const std::string path = fmt::format("cases[{}].", i);
      CaseView c{.broken = f.boolean((*cases)[i], "broken", path)};
      if (const json* held = f.field((*cases)[i], "item", path)) c.item = read_item(f, *held, path + "item");
      s.cases.push_back(c);
    }
  }
  s.table = read_items(f, m, "table");
  s.judged = f.integer(m, "judged");
  if (const json* players = f.field(m, "players")) {
    s.vive_connected = f.boolean(*players, "vive", "players.");
    s.phantom_connected = f.boolean(*players, "phantom", "players.");
  }
  s.targets = read_texts(f, m, "targets");
  if (!f.ok()) return Error{f.error()};
  return ServerMessage{std::move(s)};
}

std::optional<museum::EventType> event_type(const std::string& name) {
  for (int t = 0; t <= static_cast<int>(museum::EventType::round_ended); ++t) {
    const auto type = static_cast<museum::EventType>(t);
    if (name == museum::to_string(type)) return type;
  }
  return std::nullopt;
}

Result<ServerMessage> read_event(const json& m, JsonFields& f) {
  const std::string name = f.text(m, "event");
  if (!f.ok()) return Error{f.error()};
  const auto type = event_type(name);
  if (!type) return Error{fmt::format("'event' is '{}', which this client does not know", name)};
  museum::Event e{.type = *type};
  using museum::EventType;
  switch (e.type) {
    case EventType::case_broken:
      e.case_index = f.integer(m, "case");
      e.pos = field_xy(f, m, "pos");
      e.radius = f.number(m, "radius");
      break;
    case EventType::case_empty:
      e.case_index = f.integer(m, "case");
      break;
    case EventType::item_taken:
      e.case_index = f.integer(m, "case");
      e.item = f.integer(m, "item");
      break;
    case EventType::items_delivered:
      e.count = f.integer(m, "count");
      break;
    case EventType::guard_heard:
      e.guard = f.integer(m, "guard");
      e.pos = field_xy(f, m, "pos");
      e.radius = f.number(m, "radius");
      break;
    case EventType::vive_caught:
      e.guard = f.integer(m, "guard");
      e.count = f.integer(m, "items_lost");
      e.pos = field_xy(f, m, "pos");
      break;
    case EventType::verdict: {
      e.item = f.integer(m, "item");
      const std::string v = f.text(m, "verdict");
      if (f.ok() && v != "genuine" && v != "forgery")
        f.fail("verdict", fmt::format("is '{}'; it must be genuine or forgery", v));
      e.verdict = v == "genuine" ? museum::Verdict::genuine : museum::Verdict::forgery;
      break;
    }
    case EventType::time_warning:
      e.count = f.integer(m, "seconds_left");
      break;
    case EventType::round_ended:
      break;
  }
  if (!f.ok()) return Error{f.error()};
  return ServerMessage{GameEvent{e}};
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

// the form's numbers; its kind is the message's
constexpr std::pair<const char*, double museum::PieceForm::*> kFormNumbers[] = {
    {"feature", &museum::PieceForm::feature},
    {"stiffness", &museum::PieceForm::stiffness},
    {"friction_static", &museum::PieceForm::friction_static},
    {"friction_dynamic", &museum::PieceForm::friction_dynamic},
};

Result<ServerMessage> read_in_hand(const json& m, JsonFields& f) {
  InHand h;
  const json* item = f.field(m, "item");
  if (item != nullptr && !item->is_null()) {
    h.item = f.integer(m, "item");
    h.kind = f.text(m, "kind");
    h.form.kind = h.kind;
    if (const json* form = f.field(m, "form")) {
      h.form.difficulty = read_difficulty(f, *form, "form.");
      for (const auto& [name, value] : kFormNumbers) h.form.*value = f.number(*form, name, "form.");
    }
  }
  if (!f.ok()) return Error{f.error()};
  return ServerMessage{h};
}

Result<ServerMessage> read_summary(const json& m, JsonFields& f) {
  Summary s;
  if (const json* score = f.field(m, "score")) {
    s.points = f.integer(*score, "points", "score.");
    s.genuine_kept = f.integer(*score, "genuine_kept", "score.");
    s.forgeries_kept = f.integer(*score, "forgeries_kept", "score.");
    s.genuine_rejected = f.integer(*score, "genuine_rejected", "score.");
    s.forgeries_rejected = f.integer(*score, "forgeries_rejected", "score.");
    s.time_bonus = f.integer(*score, "time_bonus", "score.");
  }
  if (const json* targets = f.array(m, "targets")) {
    for (std::size_t i = 0; i < targets->size() && f.ok(); ++i) {
      const std::string path = fmt::format("targets[{}].", i);
      const json& t = (*targets)[i];
      s.targets.push_back({f.text(t, "kind", path), f.text(t, "genuine", path), f.text(t, "forgery", path)});
    }
  }
  s.times_caught = f.integer(m, "times_caught");
  s.seconds_played = f.number(m, "seconds_played");
  s.ended_early = f.boolean(m, "ended_early");
  if (!f.ok()) return Error{f.error()};
  return ServerMessage{s};
}

Result<ServerMessage> read_error(const json& m, JsonFields& f) {
  ServerError e{.id = id_of(m)};
  if (const json* request = f.optional(m, "request"); request != nullptr && request->is_string())
    e.request = request->get<std::string>();
  e.message = f.text(m, "message");
  if (!f.ok()) return Error{f.error()};
  return ServerMessage{e};
}

Result<ServerMessage> read_pong(const json& m, JsonFields& f) {
  Pong p{.id = id_of(m)};
  p.tick = f.integer(m, "tick");
  if (!f.ok()) return Error{f.error()};
  return ServerMessage{p};
}

}  // namespace

Result<ServerMessage> read_server_message(std::string_view text) {
  auto document = read_object(text);
  if (!document) return document.error();
  const json& m = *document;
  if (!m.is_object()) return Error{"the message is not a JSON object"};
  JsonFields f;
  const std::string type = f.text(m, "type");
  if (!f.ok()) return Error{f.error()};
  if (type == "welcome") return read_welcome(m, f);
  if (type == "snapshot") return read_snapshot(m, f);
  if (type == "event") return read_event(m, f);
  if (type == "in_hands") return read_in_hand(m, f);
  if (type == "summary") return read_summary(m, f);
  if (type == "error") return read_error(m, f);
  if (type == "pong") return read_pong(m, f);
  return Error{fmt::format("'type' is '{}', which this client does not know", type)};
}

std::string write_message(const Welcome& m) {
  json welcome = {{"type", "welcome"},
                  {"id", m.id},
                  {"protocol", m.protocol},
                  {"role", m.role},
                  {"level", level_json(m.level)},
                  {"targets", m.targets}};
  if (!m.seat_key.empty()) welcome["seat_key"] = m.seat_key;
  return text(welcome);
}

namespace {

json item_json(const ItemView& it) { return {{"item", it.item}, {"kind", it.kind}}; }

json items_json(const std::vector<ItemView>& items) {
  json out = json::array();
  for (const ItemView& it : items) out.push_back(item_json(it));
  return out;
}

}  // namespace

std::string write_message(const Snapshot& s) {
  json guards = json::array();
  for (const GuardView& g : s.guards)
    guards.push_back({{"pos", xy(g.pos)}, {"facing", xy(g.facing)}, {"mode", g.mode}});
  json cases = json::array();
  for (const CaseView& c : s.cases)
    cases.push_back({{"broken", c.broken}, {"item", c.item.item >= 0 ? item_json(c.item) : json(nullptr)}});
  return text(json{{"type", "snapshot"},
                   {"tick", s.tick},
                   {"time_left_s", s.time_left_s},
                   {"phase", s.phase},
                   {"players", {{"vive", s.vive_connected}, {"phantom", s.phantom_connected}}},
                   {"targets", s.targets},
                   {"vive",
                    {{"pos", xy(s.vive_pos)},
                     {"facing", xy(s.vive_facing)},
                     {"running", s.vive_running},
                     {"carried", items_json(s.carried)},
                     {"times_caught", s.times_caught}}},
                   {"guards", guards},
                   {"cases", cases},
                   {"table", items_json(s.table)},
                   {"judged", s.judged}});
}

std::string write_message(const GameEvent& m) { return text(event_json(m.event)); }

std::string write_message(const InHand& m) {
  json form = {{"difficulty", museum::to_string(m.form.difficulty)}};
  for (const auto& [name, value] : kFormNumbers) form[name] = m.form.*value;
  return text(json{{"type", "in_hands"}, {"item", m.item}, {"kind", m.kind}, {"form", form}});
}

std::string write_message(const Summary& s) {
  json targets = json::array();
  for (const TargetView& t : s.targets)
    targets.push_back({{"kind", t.kind}, {"genuine", t.genuine}, {"forgery", t.forgery}});
  return text(json{{"type", "summary"},
                   {"targets", targets},
                   {"score",
                    {{"points", s.points},
                     {"genuine_kept", s.genuine_kept},
                     {"forgeries_kept", s.forgeries_kept},
                     {"genuine_rejected", s.genuine_rejected},
                     {"forgeries_rejected", s.forgeries_rejected},
                     {"time_bonus", s.time_bonus}}},
                   {"times_caught", s.times_caught},
                   {"seconds_played", s.seconds_played},
                   {"ended_early", s.ended_early}});
}

std::string write_message(const ServerError& m) {
  return text(json{{"type", "error"}, {"id", m.id}, {"request", m.request}, {"message", m.message}});
}

std::string write_message(const Pong& m) {
  return text(json{{"type", "pong"}, {"id", m.id}, {"tick", m.tick}});
}

}  // namespace uh::museum_protocol
