#pragma once
/// \file
/// GameServer: the museum heist's authoritative server (`uh museum serve`).
///
/// Runs the rules (uh/museum/rules.hpp) at their fixed tick on the network thread of a
/// WebSocketHost (the stack of `uh serve`), takes Vive's moves and actions and Phantom's verdicts
/// over `ws://HOST:PORT/ws` and sends every client snapshots (20-30 Hz), events and the end
/// summary, in the versioned JSON messages of docs/museum.md. The round plays while a Vive and a
/// Phantom are connected; when either drops out it pauses (the station zeroes Phantom's force on
/// the paused snapshot) and a reconnect in that role resumes it. Phantom alone is told the piece
/// it holds (`in_hands`: its form, never whether it is genuine): its station builds that piece
/// under the device. The messages are uh::museum_protocol's. A bad message gets an error
/// naming what is wrong and is logged; the connection stays usable.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "uh/core/result.hpp"
#include "uh/museum/game_state.hpp"
#include "uh/museum/level.hpp"
#include "uh/net/web_socket_host.hpp"

namespace uh::museum_service {

/// How the server listens and which round it plays (aggregate; Box2D-style defaults).
struct GameServerOptions {
  std::string host = "127.0.0.1";  ///< an IP address or "localhost"
  std::uint16_t port = 7780;       ///< 0: any free port (see GameServer::port())
  /// Clients must present it in `hello`; required when `host` is not a loopback address.
  std::string token{};
  /// Must validate and carry its pieces (museum_artifacts::piece_pairs).
  museum::Level level = museum::make_level(museum::Difficulty::easy);
  std::uint64_t seed = 1;
  double snapshot_hz = 20.0;                 ///< snapshots per second of game time, 20..30
  /// Game seconds per second of the wall clock, 0.1..20: 1 for people; a round of bots only may
  /// run faster (`uh museum play --bots --speed`).
  double speed = 1.0;
  /// A paused round plays again this long [s, wall clock] after both players are back (its first
  /// start is at once): a player who reconnects over and over never moves it. 0..600.
  double resume_delay_s = 1.0;
  /// With a token: Phantom's seat is held this long [s] after its station dropped out; meanwhile
  /// only a hello with the station's `seat_key` takes it (token holders cannot). 0..3600.
  double seat_hold_s = 60.0;
  std::vector<net::StaticFile> files{};  ///< the browser client's files, if any
};

class GameServer {
 public:
  /// Validates the level and the options, binds and starts the network thread (the round waits
  /// for its two players). Errors name the option or the level's part that is wrong.
  static Result<std::unique_ptr<GameServer>> start(GameServerOptions options);
  /// stop().
  ~GameServer();
  GameServer(const GameServer&) = delete;
  GameServer& operator=(const GameServer&) = delete;

  std::uint16_t port() const;
  /// "http://HOST:PORT/".
  std::string url() const;
  /// A copy of the round's state, taken on the network thread. Not from the network thread.
  museum::GameState state();
  /// Messages the server refused since it started (each also logged as a warning).
  std::uint64_t refused_messages();
  /// Closes every client and joins the network thread. Idempotent.
  void stop();

 private:
  struct Impl;
  explicit GameServer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace uh::museum_service
