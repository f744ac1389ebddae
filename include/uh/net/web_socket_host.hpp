#pragma once
/// \file
/// WebSocketHost: the network half of a WebSocket server (Boost.Beast), shared by `uh serve` and
/// `uh museum serve`.
///
/// One port serves `ws://HOST:PORT/ws` and static files over HTTP (`/` is `/index.html`). What the
/// messages mean is the Endpoint's business: the host accepts connections, reads each client's
/// messages into the endpoint and writes the endpoint's replies in order, on its own network
/// thread (the io_context's only thread), where the endpoint runs too, so the endpoint needs no
/// locks. Listening off loopback needs a token (the endpoint checks it in its own greeting).

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "uh/core/result.hpp"

namespace boost::asio {
class io_context;
}

namespace uh::net {

/// A file served over HTTP at `path` (e.g. "/index.html"). The text must outlive the server.
struct StaticFile {
  std::string path{};
  std::string content_type{};
  std::string_view body{};
};

/// One connected client as the endpoint sees it. Implemented by the WebSocket connection.
class Peer {
 public:
  virtual ~Peer() = default;
  /// Queues a text message. `state` messages replace an unsent older one (a slow client gets the
  /// newest state, not a growing backlog).
  virtual void send(std::string text, bool is_state = false) = 0;
  /// Sends a close frame with `code` (RFC 6455) after the queued messages.
  virtual void close(std::uint16_t code, std::string_view reason) = 0;
  /// Bytes of messages queued for this client and not yet written (state messages aside): an
  /// endpoint refuses a request whose large reply would pile up behind a client that does not read.
  virtual std::size_t queued_bytes() const = 0;
  /// The client's address ("127.0.0.1:50412"), for the log.
  virtual const std::string& address() const = 0;
};

/// The logic behind the socket. Every call comes on the host's network thread.
class Endpoint {
 public:
  using ClientId = std::uint64_t;
  virtual ~Endpoint() = default;
  /// A client completed the WebSocket handshake; `peer` stays valid until disconnect().
  virtual ClientId connect(Peer& peer) = 0;
  virtual void receive(ClientId client, std::string_view text) = 0;
  virtual void receive_binary(ClientId client, std::span<const std::byte> bytes) = 0;
  /// The largest message the client may send next [bytes]; larger ones close it (code 1009).
  virtual std::size_t message_limit(ClientId client) const = 0;
  virtual void disconnect(ClientId client) = 0;
  /// The host is stopping: end what runs and close every client.
  virtual void shutdown() = 0;
};

/// Whether a client's token is the expected one; compares without stopping at the first
/// difference (the time does not tell how much matched).
bool same_token(std::string_view given, std::string_view expected);

/// How the host listens (aggregate; Box2D-style defaults).
struct HostOptions {
  std::string host = "127.0.0.1";  ///< an IP address or "localhost"
  std::uint16_t port = 0;          ///< 0: any free port (see WebSocketHost::port())
  bool has_token = false;          ///< clients must present a token (required off loopback)
  std::vector<StaticFile> files{};
  /// What a plain GET of /ws answers, and what an HTTP request for a missing page says.
  std::string ws_description = "this is a WebSocket endpoint";
  std::string no_page = "this build has no page\n";
  /// Names the program in the rare messages the host prints itself (e.g. "uh serve").
  std::string program = "uh";
  /// At most this many connections (HTTP and WebSocket) at once; one more is answered with HTTP
  /// 503 and closed. Each holds at most the endpoint's message limit and its outbox.
  int max_connections = 500;
};

class WebSocketHost {
 public:
  using MakeEndpoint = std::function<std::unique_ptr<Endpoint>(boost::asio::io_context&)>;

  /// Makes the endpoint with the host's io_context, binds and starts the network thread.
  /// Errors: a non-loopback host without a token, an address that does not parse, a port in use.
  static Result<std::unique_ptr<WebSocketHost>> start(HostOptions options, const MakeEndpoint& make_endpoint);
  /// stop().
  ~WebSocketHost();
  WebSocketHost(const WebSocketHost&) = delete;
  WebSocketHost& operator=(const WebSocketHost&) = delete;

  /// The port listened on (the chosen one when HostOptions::port was 0).
  std::uint16_t port() const;
  /// "http://HOST:PORT/".
  std::string url() const;
  /// The endpoint; touch it only on the network thread (see run_on_network_thread()).
  Endpoint& endpoint();
  /// Runs `call` on the network thread and waits for it. Not from the network thread itself.
  void run_on_network_thread(const std::function<void()>& call);
  /// Whether stop() was called.
  bool stopped() const;

  /// Shuts the endpoint down, closes every connection (WebSocket close 1001 from the endpoint,
  /// sockets closed after a second's grace) and joins the network thread. Idempotent. Not from
  /// the network thread.
  void stop();

 private:
  struct Impl;
  explicit WebSocketHost(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace uh::net
