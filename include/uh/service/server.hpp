#pragma once
/// \file
/// Server: haptic sessions as a service over WebSocket (`uh serve`), and the live view's page.
///
/// One port serves `ws://HOST:PORT/ws` (the JSON protocol of docs/protocol.md) and the files of
/// the live view over HTTP (`/` is `/index.html`). At most one session is open at a time: the
/// client that opened it controls it (edits, start, stop); every other client may watch it (its
/// scene, meshes, the state stream, contact events). When the controlling client disconnects, its
/// session stops (zero force at once). The server runs its own network thread (a WebSocketHost,
/// uh/net/web_socket_host.hpp); sessions run their own haptic and collision threads.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "uh/controllers/haptic_session.hpp"
#include "uh/core/result.hpp"
#include "uh/net/web_socket_host.hpp"

namespace uh::service {

/// How the server listens and what it serves (aggregate; Box2D-style defaults).
struct ServerOptions {
  std::string host = "127.0.0.1";  ///< an IP address or "localhost"
  std::uint16_t port = 7770;       ///< 0: any free port (see Server::port())
  /// Clients must present it in `hello`; required when `host` is not a loopback address.
  std::string token{};
  std::vector<net::StaticFile> files{};  ///< the live view's page and script
  std::filesystem::path cache_dir{};    ///< where .ist builds are cached; empty: the default
  std::filesystem::path working_dir{};  ///< relative paths in requests; empty: the current folder
  /// Clients may name only files in `working_dir` and `cache_dir` (scenes, meshes, .ist files, a
  /// device's trajectory, and the files a scene names); true: any file the server's user can read.
  bool allow_any_path = false;
  bool raise_priority = false;  ///< sessions ask for SCHED_FIFO (as `uh run`)
  /// Connections served at once; one more is answered with HTTP 503 (docs/protocol.md).
  int max_connections = 500;
};

class Server {
 public:
  /// Binds and starts the network thread. Errors: a non-loopback host without a token, an
  /// address that does not parse, a port in use.
  static Result<std::unique_ptr<Server>> start(ServerOptions options);
  /// stop().
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  /// The port listened on (the chosen one when ServerOptions::port was 0).
  std::uint16_t port() const;
  /// "http://HOST:PORT/".
  std::string url() const;

  /// Runs `session` as the program's own (no client controls it; clients watch it): the calling
  /// thread runs HapticSession::run(seconds, on_status, trace), so it ends as run() ends (its time
  /// up, request_stop(), a thread that ended by itself) and returns what run() returned. Blocks the
  /// calling thread, which owns the session meanwhile. An error when a client's session is open.
  /// Not concurrently with stop().
  Status run_session(controllers::HapticSession& session, double seconds,
                     const std::function<void(const controllers::SessionState&)>& on_status = {},
                     std::ostream* trace = nullptr);

  /// Stops any running session (zero force), closes every connection (WebSocket close 1001) and
  /// joins the network thread. Idempotent. Not from the network thread.
  void stop();

 private:
  struct Impl;
  explicit Server(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace uh::service
