#pragma once
/// \file
/// The museum heist's messages (docs/museum.md, "Messages", protocol 1), both ways, as plain
/// structs with one reader and one writer each: the server reads what clients send and writes
/// what it tells them; the station and the bots read what the server tells and write what they
/// send. Readers never throw on any input (fuzz/museum_protocol_fuzz.cpp): a message that does not
/// read is an error naming the field and what is wrong. Fields are read through uh::JsonFields,
/// behind the project's nesting guard.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "uh/core/result.hpp"
#include "uh/museum/level.hpp"
#include "uh/museum/rules.hpp"

namespace uh::museum_protocol {

/// The message format this build speaks (`hello.protocol`, `welcome.protocol`).
inline constexpr int kProtocolVersion = 1;

enum class Role : std::uint8_t { none, vive, phantom, watcher };
const char* to_string(Role role);
/// The role named `name` (vive, phantom or watcher), or none.
std::optional<Role> role_named(std::string_view name);

// ---- client to server

struct HelloMessage {
  int protocol = kProtocolVersion;
  Role role = Role::none;
  std::string token{};     ///< empty when absent
  std::string seat_key{};  ///< Phantom's reconnect: the key its first welcome gave; empty when absent
};
/// Vive's wanted direction (at most unit length) and pace; held until the next move.
struct MoveMessage {
  museum::Vec2 move{};
  bool run = false;
};
enum class Action : std::uint8_t { break_case, take, deliver };
const char* to_string(Action action);
/// One of Vive's actions, applied once at the next tick.
struct ActionMessage {
  Action action = Action::break_case;
};
/// Phantom's verdict on the artifact in hand (the first on the table), named so that a verdict
/// that comes late or twice never lands on the next one.
struct VerdictMessage {
  int item = -1;
  museum::Verdict verdict = museum::Verdict::none;
};
struct PingMessage {};
using ClientMessage = std::variant<HelloMessage, MoveMessage, ActionMessage, VerdictMessage, PingMessage>;

/// One client message as the server reads it: the body, or what is wrong with it. `id` and `type`
/// are kept whenever they could be read, so that the error reply can echo them.
struct ParsedClientMessage {
  nlohmann::json id = nullptr;  ///< echoed in the reply; null when absent
  std::string type{};
  std::optional<ClientMessage> body{};
  std::string error{};  ///< why there is no body
};
ParsedClientMessage read_client_message(std::string_view text);

std::string write_message(const HelloMessage& m);
std::string write_message(const MoveMessage& m);
std::string write_message(const ActionMessage& m);
std::string write_message(const VerdictMessage& m);

// ---- server to client

/// An artifact as clients see it: its index in the round and its kind's name (item -1: none).
struct ItemView {
  int item = -1;
  std::string kind{};
};

/// `welcome`: the level (rooms, cases, the table, the kinds, the rule numbers clients are told:
/// museum::kRuleFields `told`) and the round's targets. Never the seed: a client given it could
/// deal the round itself.
struct Welcome {
  nlohmann::json id = nullptr;  ///< the hello's id
  int protocol = kProtocolVersion;
  std::string role{};
  /// Phantom's only: the key that takes its seat again after a dropped connection (hello.seat_key).
  std::string seat_key{};
  museum::Level level{};  ///< its rooms, cases, table, entrance, kinds and told rule numbers
  std::vector<std::string> targets{};
};

struct GuardView {
  museum::Vec2 pos{};
  museum::Vec2 facing{1.0, 0.0};
  std::string mode{};  ///< patrol, investigate or returning
};

/// A display case as clients see it.
struct CaseView {
  bool broken = false;
  ItemView item{};  ///< what it holds (item -1: nothing)
};

/// `snapshot`: the round as every client may see it (never which piece is genuine, nor the points).
struct Snapshot {
  std::int64_t tick = 0;
  double time_left_s = 0.0;
  std::string phase{};  ///< waiting, playing, paused or ended
  bool vive_connected = false;
  bool phantom_connected = false;
  std::vector<std::string> targets{};
  museum::Vec2 vive_pos{};
  museum::Vec2 vive_facing{1.0, 0.0};
  bool vive_running = false;
  int times_caught = 0;
  std::vector<ItemView> carried{};
  std::vector<GuardView> guards{};
  std::vector<CaseView> cases{};
  std::vector<ItemView> table{};  ///< in the order Phantom judges them
  int judged = 0;
};

/// `event`: the rules' event (a verdict's `correct` is not told during the round).
struct GameEvent {
  museum::Event event{};
};

/// `in_hands` (Phantom only): the artifact that came to the front of the table and the form the
/// station builds it from, which never says whether it is genuine (item -1: nothing in hand).
struct InHand {
  int item = -1;
  std::string kind{};
  museum::PieceForm form{};
};

/// Where a target's two pieces ended (`kept`, `rejected`, `in_case`, ... as museum::to_string
/// names a museum::ItemPlace).
struct TargetView {
  std::string kind{};
  std::string genuine{};
  std::string forgery{};
};

/// `summary`: the end of the round (now the pieces may be told).
struct Summary {
  int points = 0;
  int genuine_kept = 0;
  int forgeries_kept = 0;
  int genuine_rejected = 0;
  int forgeries_rejected = 0;
  int time_bonus = 0;
  std::vector<TargetView> targets{};
  int times_caught = 0;
  double seconds_played = 0.0;
  bool ended_early = false;  ///< every target settled before the time ran out
};

/// `error`: a request the server refused.
struct ServerError {
  nlohmann::json id = nullptr;  ///< the request's id
  std::string request{};        ///< its type
  std::string message{};
};

/// `pong`: the answer to a ping, with the rules' tick.
struct Pong {
  nlohmann::json id = nullptr;
  std::int64_t tick = 0;
};

using ServerMessage = std::variant<Welcome, Snapshot, GameEvent, InHand, Summary, ServerError, Pong>;

/// Reads one text frame from the server. Errors name the field and what is wrong.
Result<ServerMessage> read_server_message(std::string_view text);

std::string write_message(const Welcome& m);
std::string write_message(const Snapshot& m);
std::string write_message(const GameEvent& m);
std::string write_message(const InHand& m);
std::string write_message(const Summary& m);
std::string write_message(const ServerError& m);
std::string write_message(const Pong& m);

}  // namespace uh::museum_protocol
