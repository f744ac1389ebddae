#pragma once
// The museum server's JSON messages (docs/museum.md): what clients send, parsed and checked field
// by field (never throwing, every error naming the field), and what the server sends.

#include <optional>
#include <string>
#include <string_view>
#include <variant>

#include <nlohmann/json.hpp>

#include "uh/museum/rules.hpp"

namespace uh::museum_service {

using nlohmann::json;

enum class Role : std::uint8_t { none, vive, phantom, watcher };
const char* to_string(Role role);

struct HelloMessage {
  int protocol = 0;
  Role role = Role::none;
  std::string token{};     // empty when absent
  std::string seat_key{};  // Phantom's reconnect: the key its first welcome gave; empty when absent
};
/// Vive's wanted direction and pace; held until the next move.
struct MoveMessage {
  museum::Vec2 move{};
  bool run = false;
};
enum class Action : std::uint8_t { break_case, take, deliver };
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

struct ParsedMessage {
  json id = nullptr;  // echoed in the reply; null when absent
  std::string type{};
  std::optional<ClientMessage> body{};
  std::string error{};  // why there is no body
};
ParsedMessage parse_message(std::string_view text);

json error_message(const json& id, std::string_view request_type, std::string_view message);
json level_json(const museum::Level& level);
/// The state as every client may see it: never which artifact is genuine, nor the points before
/// the end (a verdict's points would tell).
json snapshot_json(const museum::Level& level, const museum::GameState& state, std::string_view phase,
                   bool vive_connected, bool phantom_connected);
json event_json(const museum::Event& event);
/// To Phantom only: the artifact in its hands (`item`, the first on the table), its `kind` and which
/// `piece` it is (genuine or forgery), for the station to load the right object under the device.
/// The player is never told; only what the device renders of it tells.
json in_hands_json(const museum::Level& level, const museum::GameState& state, int item);
json summary_json(const museum::Level& level, const museum::RoundSummary& summary);

}  // namespace uh::museum_service
