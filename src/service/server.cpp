#include "uh/service/server.hpp"

#include <utility>

#include "hub.hpp"
#include "uh/net/web_socket_host.hpp"

namespace uh::service {

// the network (WebSocketHost) with the hub as its endpoint
struct Server::Impl {
  std::unique_ptr<net::WebSocketHost> host;
  Hub* hub = nullptr;  // the host's endpoint: the network thread's
};

Server::Server(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

Server::~Server() { stop(); }

Result<std::unique_ptr<Server>> Server::start(ServerOptions options) {
  HubOptions hub_options{
      .token = options.token,
      .cache_dir = options.cache_dir.empty() ? controllers::default_cache_dir() : options.cache_dir,
      .working_dir = options.working_dir.empty() ? std::filesystem::current_path() : options.working_dir,
      .folders = {},
      .raise_priority = options.raise_priority};
  if (!options.allow_any_path)
    hub_options.folders = ReadableFolders({{.path = hub_options.working_dir, .label = ""},
                                           {.path = hub_options.cache_dir, .label = "<cache>"}});
  auto impl = std::make_unique<Impl>();
  Hub* hub = nullptr;
  auto host = net::WebSocketHost::start(
      {.host = options.host,
       .port = options.port,
       .has_token = !options.token.empty(),
       .files = std::move(options.files),
       .ws_description = "this is the WebSocket endpoint of the uh service (docs/protocol.md)\n",
       .no_page = "this build of uh has no live view\n",
       .program = "uh serve",
       .max_connections = options.max_connections},
      [&](boost::asio::io_context& io) {
        auto made = std::make_unique<Hub>(io, std::move(hub_options));
        hub = made.get();
        return made;
      });
  if (!host) return host.error();
  impl->host = std::move(host).value();
  impl->hub = hub;
  return std::unique_ptr<Server>(new Server(std::move(impl)));
}

std::uint16_t Server::port() const { return impl_->host->port(); }

std::string Server::url() const { return impl_->host->url(); }

Status Server::run_session(controllers::HapticSession& session, double seconds,
                           const std::function<void(const controllers::SessionState&)>& on_status,
                           std::ostream* trace) {
  if (impl_->host->stopped()) return Error{"the server is stopped"};
  // the hub is the network thread's: show() and unshow() run there, and this thread waits
  Status shown = Ok{};
  impl_->host->run_on_network_thread([&] { shown = impl_->hub->show(session); });
  if (!shown) return shown;
  // run() on this thread, as `uh run` without the view: the session's time, request_stop() (a
  // signal handler's), a thread that ends by itself, each with zero force and the same report
  Status ran = session.run(seconds, on_status, trace);
  impl_->host->run_on_network_thread([&] { impl_->hub->unshow(); });
  return ran;
}

void Server::stop() {
  if (impl_ && impl_->host) impl_->host->stop();
}

}  // namespace uh::service
