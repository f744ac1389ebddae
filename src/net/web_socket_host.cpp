#include "uh/net/web_socket_host.hpp"

#include <atomic>
#include <chrono>
#include <cstdio>
#include <deque>
#include <functional>
#include <future>
#include <map>
#include <optional>
#include <set>
#include <span>
#include <thread>

#include <fmt/format.h>
#include <boost/asio/co_spawn.hpp>
#include <boost/asio/detached.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/redirect_error.hpp>
#include <boost/asio/use_awaitable.hpp>
#include <boost/asio/write.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

namespace uh::net {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using namespace std::chrono_literals;

// A client that stops reading is closed once this much waits to be sent to it.
constexpr std::size_t kMaxOutboxBytes = 64u << 20;

// Connections beyond the limit being told so at once; more are closed without an answer.
constexpr int kMaxRefusing = 16;

// Coroutines end on errors they see; anything thrown is a bug, reported and contained.
auto exception_reporter(std::string program) {
  return [program = std::move(program)](const std::exception_ptr& e) {
    if (!e) return;
    try {
      std::rethrow_exception(e);
    } catch (const std::exception& x) {
      std::fprintf(stderr, "%s: connection ended by an internal error: %s\n", program.c_str(), x.what());
    }
  };
}

// The sockets of the connections being served, so that stopping the server can close those whose
// clients do not answer the close handshake (network thread).
using OpenSockets = std::set<tcp::socket*>;

// Keeps a socket in OpenSockets while in scope.
class SocketEntry {
 public:
  SocketEntry(OpenSockets& open, tcp::socket& socket) : open_(open), socket_(&socket) {
    open_.insert(socket_);
  }
  ~SocketEntry() { open_.erase(socket_); }
  SocketEntry(const SocketEntry&) = delete;
  SocketEntry& operator=(const SocketEntry&) = delete;

 private:
  OpenSockets& open_;
  tcp::socket* socket_;
};

// One WebSocket client: reads requests into the endpoint, writes its queued replies in order.
class Connection final : public Peer, public std::enable_shared_from_this<Connection> {
 public:
  Connection(beast::tcp_stream stream, Endpoint& hub, OpenSockets& open, const std::string& program)
      : ws_(std::move(stream)), hub_(hub), open_(open), program_(program), wake_(ws_.get_executor()) {
    beast::error_code ec;
    const auto remote = beast::get_lowest_layer(ws_).socket().remote_endpoint(ec);
    address_ = ec ? std::string("?") : fmt::format("{}:{}", remote.address().to_string(), remote.port());
  }

  asio::awaitable<void> run(http::request<http::string_body> request) {
    auto self = shared_from_this();
    const SocketEntry entry(open_, beast::get_lowest_layer(ws_).socket());
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    beast::error_code ec;
    co_await ws_.async_accept(request, asio::redirect_error(asio::use_awaitable, ec));
    if (ec) co_return;
    id_ = hub_.connect(*this);
    connected_ = true;
    asio::co_spawn(ws_.get_executor(), write_loop(), exception_reporter(program_));
    beast::flat_buffer buffer;
    for (;;) {
      // the endpoint's limit for this client's next message (uh serve: larger only for the binary
      // frame an add_object announced)
      ws_.read_message_max(hub_.message_limit(id_));
      co_await ws_.async_read(buffer, asio::redirect_error(asio::use_awaitable, ec));
      // a message above read_message_max fails here after Beast sent close 1009 (too big)
      if (ec) break;
      if (ws_.got_text())
        hub_.receive(id_, std::string_view(static_cast<const char*>(buffer.data().data()), buffer.size()));
      else
        hub_.receive_binary(id_,
                            std::span(static_cast<const std::byte*>(buffer.data().data()), buffer.size()));
      buffer.consume(buffer.size());
    }
    finished_ = true;
    wake_.cancel();
    connected_ = false;
    hub_.disconnect(id_);
  }

  void send(std::string text, bool is_state) override {
    if (finished_ || close_code_ != 0) return;
    if (is_state) {
      state_ = std::move(text);
    } else {
      outbox_bytes_ += text.size();
      outbox_.push_back(std::move(text));
      if (outbox_bytes_ > kMaxOutboxBytes) {
        outbox_.clear();
        outbox_bytes_ = 0;
        close(1008, "the client does not read its messages");
      }
    }
    wake_.cancel();
  }

  std::size_t queued_bytes() const override { return outbox_bytes_; }
  const std::string& address() const override { return address_; }

  void close(std::uint16_t code, std::string_view reason) override {
    if (close_code_ != 0) return;
    close_code_ = code;
    close_reason_ = reason;
    state_.reset();
    wake_.cancel();
  }

 private:
  asio::awaitable<void> write_loop() {
    auto self = shared_from_this();
    beast::error_code ec;
    while (!finished_) {
      if (outbox_.empty() && !state_ && close_code_ == 0) {
        wake_.expires_at(asio::steady_timer::time_point::max());
        co_await wake_.async_wait(asio::redirect_error(asio::use_awaitable, ec));
        continue;
      }
      std::string message;
      if (!outbox_.empty()) {
        message = std::move(outbox_.front());
        outbox_.pop_front();
        outbox_bytes_ -= message.size();
      } else if (state_) {
        message = std::move(*state_);
        state_.reset();
      } else {
        // everything queued before the close went out first (e.g. the error naming the reason)
        websocket::close_reason reason;
        reason.code = close_code_;
        reason.reason = close_reason_;
        co_await ws_.async_close(reason, asio::redirect_error(asio::use_awaitable, ec));
        co_return;
      }
      ws_.text(true);
      co_await ws_.async_write(asio::buffer(message), asio::redirect_error(asio::use_awaitable, ec));
      if (ec) co_return;
    }
  }

  websocket::stream<beast::tcp_stream> ws_;
  Endpoint& hub_;
  OpenSockets& open_;
  const std::string& program_;
  asio::steady_timer wake_;  // the writer waits on it; cancel() wakes it
  Endpoint::ClientId id_ = 0;
  bool connected_ = false;
  bool finished_ = false;
  std::deque<std::string> outbox_;
  std::size_t outbox_bytes_ = 0;
  std::optional<std::string> state_;  // the newest unsent state message
  std::uint16_t close_code_ = 0;
  std::string close_reason_;
  std::string address_;
};

std::string_view path_of(std::string_view target) {
  const auto q = target.find('?');
  return q == std::string_view::npos ? target : target.substr(0, q);
}

}  // namespace

bool same_token(std::string_view given, std::string_view expected) {
  if (given.size() != expected.size()) return false;
  unsigned diff = 0;
  for (std::size_t i = 0; i < given.size(); ++i)
    diff |=
        static_cast<unsigned>(static_cast<unsigned char>(given[i]) ^ static_cast<unsigned char>(expected[i]));
  return diff == 0;
}

struct WebSocketHost::Impl {
  explicit Impl(HostOptions o) : options(std::move(o)), acceptor(io), stop_timer(io) {
    for (const StaticFile& f : options.files) files[f.path] = &f;
  }

  http::response<http::string_body> respond(const http::request<http::string_body>& req) const {
    http::response<http::string_body> res;
    res.version(req.version());
    res.keep_alive(req.keep_alive());
    res.set(http::field::server, "uh");
    res.set(http::field::cache_control, "no-store");
    const auto text = [&](http::status status, std::string body) {
      res.result(status);
      res.set(http::field::content_type, "text/plain; charset=utf-8");
      res.body() = std::move(body);
    };
    std::string_view path = path_of(std::string_view(req.target().data(), req.target().size()));
    if (path == "/") path = "/index.html";
    if (req.method() != http::verb::get && req.method() != http::verb::head) {
      text(http::status::method_not_allowed, "only GET and HEAD\n");
    } else if (path == "/ws") {
      text(http::status::upgrade_required, options.ws_description);
    } else if (const auto it = files.find(std::string(path)); it != files.end()) {
      res.result(http::status::ok);
      res.set(http::field::content_type, it->second->content_type);
      res.set("X-Content-Type-Options", "nosniff");
      res.body() = std::string(it->second->body);
    } else if (files.empty() && path == "/index.html") {
      text(http::status::not_found, options.no_page);
    } else {
      text(http::status::not_found, "not found\n");
    }
    res.prepare_payload();
    if (req.method() == http::verb::head) res.body().clear();
    return res;
  }

  asio::awaitable<void> serve(tcp::socket socket) {
    ++live;
    beast::tcp_stream stream(std::move(socket));
    beast::flat_buffer buffer;
    beast::error_code ec;
    std::optional<SocketEntry> entry(std::in_place, open_sockets, stream.socket());
    for (;;) {
      http::request_parser<http::string_body> parser;
      parser.header_limit(16 * 1024);
      parser.body_limit(64 * 1024);
      stream.expires_after(30s);
      co_await http::async_read(stream, buffer, parser, asio::redirect_error(asio::use_awaitable, ec));
      if (ec) break;
      http::request<http::string_body> req = parser.release();
      if (websocket::is_upgrade(req) &&
          path_of(std::string_view(req.target().data(), req.target().size())) == "/ws") {
        stream.expires_never();
        entry.reset();
        auto connection =
            std::make_shared<Connection>(std::move(stream), *endpoint, open_sockets, options.program);
        co_await connection->run(std::move(req));
        break;
      }
      auto res = respond(req);
      co_await http::async_write(stream, res, asio::redirect_error(asio::use_awaitable, ec));
      if (ec || !res.keep_alive()) break;
    }
    if (stream.socket().is_open()) stream.socket().shutdown(tcp::socket::shutdown_both, ec);
    if (--live == 0 && stopping) io.stop();
  }

  // one connection too many: told so in HTTP (a WebSocket client sees its handshake refused with
  // 503) without reading its request, and closed
  asio::awaitable<void> refuse(tcp::socket socket) {
    ++refusing;
    const std::string body = fmt::format("{}: too many connections (the limit is {}); try again later\n",
                                         options.program, options.max_connections);
    const std::string response = fmt::format(
        "HTTP/1.1 503 Service Unavailable\r\nContent-Type: text/plain; charset=utf-8\r\nContent-Length: "
        "{}\r\nConnection: close\r\n\r\n{}",
        body.size(), body);
    beast::tcp_stream stream(std::move(socket));
    stream.expires_after(5s);
    beast::error_code ec;
    co_await asio::async_write(stream, asio::buffer(response), asio::redirect_error(asio::use_awaitable, ec));
    stream.socket().shutdown(tcp::socket::shutdown_both, ec);
    --refusing;
  }

  asio::awaitable<void> accept() {
    for (;;) {
      beast::error_code ec;
      tcp::socket socket = co_await acceptor.async_accept(asio::redirect_error(asio::use_awaitable, ec));
      if (ec) co_return;
      if (live >= options.max_connections) {
        // a flood of them is closed without a word
        if (refusing >= kMaxRefusing) continue;
        asio::co_spawn(io, refuse(std::move(socket)), exception_reporter(options.program));
        continue;
      }
      asio::co_spawn(io, serve(std::move(socket)), exception_reporter(options.program));
    }
  }

  HostOptions options;
  asio::io_context io{1};
  tcp::acceptor acceptor;
  std::map<std::string, const StaticFile*, std::less<>> files;
  std::unique_ptr<Endpoint> endpoint;
  asio::steady_timer stop_timer;
  OpenSockets open_sockets;
  std::thread thread;
  std::uint16_t port = 0;
  std::string url;
  int live = 0;           // connections being served (network thread)
  int refusing = 0;       // connections being told that there are too many (network thread)
  bool stopping = false;  // network thread
  std::atomic<bool> stopped{false};
};

WebSocketHost::WebSocketHost(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

WebSocketHost::~WebSocketHost() { stop(); }

Result<std::unique_ptr<WebSocketHost>> WebSocketHost::start(HostOptions options,
                                                            const MakeEndpoint& make_endpoint) {
  beast::error_code ec;
  const std::string host = options.host == "localhost" ? "127.0.0.1" : options.host;
  const auto address = asio::ip::make_address(host, ec);
  if (ec)
    return Error{
        fmt::format("host '{}' is not an IP address (e.g. 127.0.0.1, ::1 or 0.0.0.0)", options.host)};
  if (!address.is_loopback() && !options.has_token)
    return Error{fmt::format(
        "host '{}' is not a loopback address: other machines could connect, so a token is required",
        options.host)};
  auto impl = std::make_unique<Impl>(std::move(options));
  impl->endpoint = make_endpoint(impl->io);
  auto& acceptor = impl->acceptor;
  const tcp::endpoint endpoint(address, impl->options.port);
  acceptor.open(endpoint.protocol(), ec);
  if (!ec) acceptor.set_option(asio::socket_base::reuse_address(true), ec);
  if (!ec) acceptor.bind(endpoint, ec);
  if (!ec) acceptor.listen(asio::socket_base::max_listen_connections, ec);
  if (ec) return Error{fmt::format("cannot listen on {}:{}: {}", host, impl->options.port, ec.message())};
  impl->port = acceptor.local_endpoint().port();
  // before the network thread starts: the acceptor is its own from then on
  const auto bound = acceptor.local_endpoint().address();
  impl->url =
      fmt::format("http://{}:{}/", bound.is_v6() ? fmt::format("[{}]", bound.to_string()) : bound.to_string(),
                  impl->port);
  asio::co_spawn(impl->io, impl->accept(), exception_reporter(impl->options.program));
  Impl* raw = impl.get();
  impl->thread = std::thread([raw] { raw->io.run(); });
  return std::unique_ptr<WebSocketHost>(new WebSocketHost(std::move(impl)));
}

std::uint16_t WebSocketHost::port() const { return impl_->port; }

std::string WebSocketHost::url() const { return impl_->url; }

Endpoint& WebSocketHost::endpoint() { return *impl_->endpoint; }

bool WebSocketHost::stopped() const { return impl_->stopped; }

void WebSocketHost::run_on_network_thread(const std::function<void()>& call) {
  std::promise<void> done;
  asio::post(impl_->io, [&] {
    call();
    done.set_value();
  });
  done.get_future().get();
}

void WebSocketHost::stop() {
  if (!impl_ || impl_->stopped.exchange(true)) return;
  Impl* impl = impl_.get();
  asio::post(impl->io, [impl] {
    impl->stopping = true;
    beast::error_code ec;
    impl->acceptor.close(ec);
    impl->endpoint->shutdown();
    if (impl->live == 0) impl->io.stop();
    // clients get a moment to answer the close handshake; then their sockets are closed, which
    // ends every connection's coroutine and so the network thread
    impl->stop_timer.expires_after(1s);
    impl->stop_timer.async_wait([impl](const beast::error_code&) {
      for (tcp::socket* socket : OpenSockets(impl->open_sockets)) {
        beast::error_code ignored;
        socket->close(ignored);
      }
      impl->stop_timer.expires_after(1s);
      impl->stop_timer.async_wait([impl](const beast::error_code&) { impl->io.stop(); });
    });
  });
  if (impl->thread.joinable()) impl->thread.join();
}

}  // namespace uh::net
