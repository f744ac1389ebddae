#pragma once
/// \file
/// GameLink: a client's connection to the museum server (Phantom's station, the automated players
/// of `uh museum play`), on its own network thread. What the server says crosses to the owner's
/// thread through an SpscQueue (parsed on the network thread: a frame that does not parse is logged
/// and reported, never thrown); what the owner sends crosses the other way through another. Nothing
/// here ever waits on a haptic thread, and a haptic thread never waits on it.
///
/// An owner that lags loses snapshots (a newer one follows), never another message. After a drop
/// the link says so once and, unless told not to, reconnects every `retry_s` (the server resumes a
/// paused round when the player says hello again).

#include <atomic>
#include <memory>
#include <string>

#include "uh/core/result.hpp"
#include "uh/museum_protocol/messages.hpp"
#include "uh/net/ws_url.hpp"

namespace uh::museum_client {

using museum_protocol::ServerMessage;
using museum_protocol::Welcome;

struct LinkOptions {
  /// ws://HOST:PORT/ws, http://HOST:PORT/ (what `uh museum serve` prints) or HOST:PORT.
  std::string url = "ws://127.0.0.1:7780/ws";
  std::string role = "phantom";  ///< said in the hello: vive, phantom or watcher
  std::string token{};           ///< sent in the hello when the server needs one
  double welcome_s = 5.0;        ///< how long connect() waits for the welcome [s]
  double retry_s = 1.0;          ///< between reconnection attempts after a drop [s]
  bool reconnect = true;         ///< false: after a drop the link stays down (a bot's round is over)
};

/// Something the network thread tells the owner.
struct LinkNote {
  enum class Kind : std::uint8_t {
    message,      ///< `message` arrived; `text` is the frame as it came (e.g. to print it)
    bad_message,  ///< a frame that did not parse: `text` says why (logged, ignored)
    dropped,      ///< the connection ended: `text` says why; the link tries again if it reconnects
    reconnected,  ///< connected again and said hello (a welcome follows)
  };
  Kind kind = Kind::message;
  ServerMessage message{};
  std::string text{};
};

class GameLink {
 public:
  /// Connects, says hello in the role and waits for the welcome. Errors: the URL is not one a
  /// client understands, the server is unreachable, it refused the hello (a wrong token, the role
  /// taken), or no welcome came.
  static Result<std::unique_ptr<GameLink>> connect(const LinkOptions& options);
  ~GameLink();
  GameLink(const GameLink&) = delete;
  GameLink& operator=(const GameLink&) = delete;

  const Welcome& welcome() const { return welcome_; }
  /// The next note from the network thread; false when none waits. Owner thread.
  bool poll(LinkNote& out);
  /// The next note, waiting for it at most `limit_s`; false when none came. Owner thread.
  bool wait(LinkNote& out, double limit_s);
  /// Queues a text frame for the server; false when the queue is full. Owner thread.
  bool send(std::string text);
  /// Whether the connection is up now. Any thread.
  bool connected() const;
  /// Closes the connection and joins the network thread. Idempotent. Owner thread.
  void stop();

 private:
  struct Impl;
  explicit GameLink(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
  Welcome welcome_{};
};

/// HOST, PORT and the WebSocket path from a URL as LinkOptions::url takes it (net::parse_ws_url
/// in the museum's forms); an error names it.
using ServerAddress = net::WsUrl;
Result<ServerAddress> parse_server_url(const std::string& url);

}  // namespace uh::museum_client
