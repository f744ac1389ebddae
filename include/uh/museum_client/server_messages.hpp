#pragma once
/// \file
/// What the museum server tells its clients (the messages of docs/museum.md, protocol 1), parsed
/// into plain data, and what they say to it. A message that does not parse is an error naming the
/// field (never an exception); GameLink logs it and carries on.

#include <cstdint>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "uh/core/result.hpp"
#include "uh/museum/level.hpp"
#include "uh/museum/piece.hpp"
#include "uh/museum/rules.hpp"

namespace uh::museum_client {

/// An artifact as clients see it: its index in the round and its kind's name.
struct ItemView {
  int item = -1;
  std::string kind{};
};

/// `welcome`: the level (rooms, cases, the table, the kinds; the rule numbers the station needs).
struct Welcome {
  std::string role{};
  /// Phantom's only: the key that takes its seat again after a dropped connection (hello.seat_key).
  std::string seat_key{};
  museum::Level level{};
  std::vector<std::string> targets{};
};

struct GuardView {
  museum::Vec2 pos{};
  museum::Vec2 facing{1.0, 0.0};
  std::string mode{};
};

/// A display case as clients see it.
struct CaseView {
  bool broken = false;
  ItemView item{};  ///< what it holds (item -1: nothing)
};

/// `snapshot`: what Vive sees (the players' connections and the targets are left out: the welcome
/// has the targets).
struct Snapshot {
  std::int64_t tick = 0;
  double time_left_s = 0.0;
  std::string phase{};  ///< waiting, playing, paused or ended
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

/// `in_hands` (Phantom only): the artifact that came to the front of the table and which piece it
/// is, so that the station renders that piece (item -1: the station's own "nothing in hand").
struct InHand {
  int item = -1;
  std::string kind{};
  museum::Piece piece = museum::Piece::genuine;
};

/// Where a target's two pieces ended (`kept`, `rejected`, `in_case`, ... as museum::to_string
/// names a museum::ItemPlace).
struct TargetView {
  std::string kind{};
  std::string genuine{};
  std::string forgery{};
};

/// `summary`: the end of the round.
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
  std::string request{};
  std::string message{};
};

/// `pong` and anything else a client does not act on.
struct Ignored {
  std::string type{};
};

using ServerMessage = std::variant<Welcome, Snapshot, GameEvent, InHand, Summary, ServerError, Ignored>;

/// Parses one text frame. Errors name the field and what is wrong (the frame is then ignored).
Result<ServerMessage> parse_server_message(std::string_view text);

/// The JSON text of a hello in `role` (vive, phantom or watcher), of Phantom's verdict and of
/// Vive's move (`move`: the direction, at most unit length) and actions (break, take, deliver).
/// `seat_key` (Phantom's reconnect, from its first welcome) is sent when not empty.
std::string hello_text(std::string_view role, std::string_view token, std::string_view seat_key = {});
std::string verdict_text(int item, museum::Verdict verdict);
std::string move_text(museum::Vec2 move, bool run);
std::string action_text(std::string_view action);

}  // namespace uh::museum_client
