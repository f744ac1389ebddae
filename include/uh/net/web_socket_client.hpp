#pragma once
/// \file
/// WebSocketClient: the project's one WebSocket client (Boost.Beast), used by the Haply driver, the
/// museum's GameLink and the tests of the servers.
///
/// It runs on its owner's thread and only inside its own calls: every call waits at most the time
/// it is given, and what is still under way when a wait ends (a read, queued writes) goes on in the
/// next call. So a driver can pace a device by the replies (send, then receive within the
/// timeout), and a connection thread can poll (receive for a few milliseconds, then send what its
/// owner queued) without a second thread or a lock.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include <boost/system/error_code.hpp>

#include "uh/core/result.hpp"
#include "uh/net/ws_url.hpp"

namespace uh::net {

/// The close frame a server sent (code 0: none came).
struct CloseReason {
  std::uint16_t code = 0;  ///< RFC 6455, e.g. 1001 going away, 1008 policy, 1009 too big
  std::string reason{};
};

class WebSocketClient {
 public:
  using Duration = std::chrono::steady_clock::duration;

  struct ConnectOptions {
    /// Names the server in the errors: "cannot reach NAME: ...", "NAME refused the WebSocket
    /// handshake: ...".
    std::string name = "the server";
    /// How long each step may take: resolving, connecting, the handshake.
    Duration step_limit = std::chrono::seconds(5);
    /// When set, connecting gives up soon after it turns true (a stopping owner).
    const std::atomic<bool>* cancel = nullptr;
  };

  /// Resolves, connects and completes the WebSocket handshake. Errors name the step and the
  /// server: "cannot resolve the host of NAME: ...", "cannot reach NAME: Connection refused",
  /// "cannot reach NAME: no answer within 2 s", "NAME refused the WebSocket handshake: ...".
  static Result<std::unique_ptr<WebSocketClient>> connect(const WsUrl& url, const ConnectOptions& options);
  /// drop().
  ~WebSocketClient();
  WebSocketClient(const WebSocketClient&) = delete;
  WebSocketClient& operator=(const WebSocketClient&) = delete;

  enum class Frame : std::uint8_t { text, binary };
  /// Queues a frame; frames are written in order while the owner waits in receive(), flush() or
  /// close(). Nothing is queued once the connection has failed.
  void send(std::string_view payload, Frame frame = Frame::text);
  /// Waits at most `limit` until every queued frame is written; false when time ran out or the
  /// connection failed.
  bool flush(Duration limit);

  enum class Received : std::uint8_t {
    message,  ///< the next message is in `out`
    nothing,  ///< none within the limit; the read goes on in the next call
    ended,    ///< the connection ended or failed (error(), close_reason())
  };
  /// Waits at most `limit` for the next message (writing queued frames meanwhile). A failed write
  /// ends the wait too: the connection is gone.
  Received receive(std::string& out, Duration limit);

  /// The closing handshake: a close frame (1000), then waits at most `limit` for the server's.
  /// False when it did not complete.
  bool close(Duration limit);
  /// Closes the socket now; whatever was under way ends (aborted) before this returns.
  void drop();

  /// No error seen yet.
  bool alive() const;
  /// A read is under way (a receive() ran out of time before its message came).
  bool reading() const;
  /// What ended the connection: empty while it is alive; websocket::error::closed after the
  /// server's close frame (see close_reason()).
  boost::system::error_code error() const;
  CloseReason close_reason() const;

 private:
  struct Impl;
  explicit WebSocketClient(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace uh::net
