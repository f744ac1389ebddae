#include "uh/museum_client/game_link.hpp"

#include <atomic>
#include <chrono>
#include <deque>
#include <thread>

#include <fmt/format.h>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>

#include "uh/core/log.hpp"
#include "uh/core/spsc_queue.hpp"

namespace uh::museum_client {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using namespace std::chrono_literals;

constexpr std::size_t kQueueCapacity = 1024;
constexpr auto kPoll = 10ms;  // how often the network thread looks at the outgoing queue and stop

}  // namespace

Result<ServerAddress> parse_server_url(const std::string& url) {
  std::string rest = url;
  ServerAddress a;
  for (const char* scheme : {"ws://", "http://"}) {
    if (rest.rfind(scheme, 0) == 0) rest = rest.substr(std::char_traits<char>::length(scheme));
  }
  if (rest.find("://") != std::string::npos)
    return Error{fmt::format("server '{}': the address must be ws://HOST:PORT/ws or http://HOST:PORT/", url)};
  const auto slash = rest.find('/');
  const std::string authority = rest.substr(0, slash);
  const auto colon = authority.rfind(':');
  if (authority.empty() || colon == std::string::npos || colon == 0 || colon + 1 == authority.size())
    return Error{fmt::format("server '{}': give the host and the port, e.g. ws://127.0.0.1:7780/ws", url)};
  a.host = authority.substr(0, colon);
  a.port = authority.substr(colon + 1);
  if (a.port.find_first_not_of("0123456789") != std::string::npos || a.port.size() > 5 ||
      std::stoi(a.port) > 65535)
    return Error{fmt::format("server '{}': the port '{}' is not a number from 0 to 65535", url, a.port)};
  return a;
}

struct GameLink::Impl {
  Impl(ServerAddress where, LinkOptions link_options)
      : address(std::move(where)), options(std::move(link_options)), timer(io), retry_timer(io) {}

  ServerAddress address;
  LinkOptions options;
  asio::io_context io;
  std::optional<websocket::stream<beast::tcp_stream>> ws;
  asio::steady_timer timer;
  asio::steady_timer retry_timer;
  beast::flat_buffer buffer;
  std::deque<std::string> writing;  // the network thread's: frames being written, in order
  std::deque<LinkNote> backlog;     // the network thread's: notes the owner had no room for yet
  bool write_busy = false;
  bool ever_connected = false;
  bool told_dropped = false;
  std::string seat_key;  // the network thread's: from the first welcome (Phantom's seat)

  SpscQueue<LinkNote> inbox{kQueueCapacity};      // network thread -> owner
  SpscQueue<std::string> outbox{kQueueCapacity};  // owner -> network thread
  std::atomic<bool> stopping{false};
  std::atomic<bool> up{false};
  std::thread thread;

  // Hands a note to the owner. When the owner lags a snapshot is dropped (the next one is newer);
  // every other note waits in the backlog, in order.
  void note(LinkNote n) {
    flush_backlog();
    if (backlog.empty() && inbox.try_push(std::move(n))) return;
    if (n.kind == LinkNote::Kind::message && std::holds_alternative<museum_protocol::Snapshot>(n.message))
      return;
    backlog.push_back(std::move(n));
  }
  void flush_backlog() {
    while (!backlog.empty() && inbox.try_push(std::move(backlog.front()))) backlog.pop_front();
  }

  void open() {
    ws.emplace(io);
    beast::get_lowest_layer(*ws).expires_after(5s);
    auto resolver = std::make_shared<tcp::resolver>(io);
    resolver->async_resolve(
        address.host, address.port,
        [this, resolver](beast::error_code ec, tcp::resolver::results_type results) {
          if (ec) return lost(ec, "cannot resolve the server's host");
          beast::get_lowest_layer(*ws).async_connect(results, [this](beast::error_code e,
                                                                     const tcp::endpoint&) {
            if (e) return lost(e, "cannot reach the server");
            beast::get_lowest_layer(*ws).expires_never();
            ws->set_option(websocket::stream_base::timeout::suggested(beast::role_type::client));
            ws->async_handshake(address.host + ":" + address.port, address.path, [this](beast::error_code h) {
              if (h) return lost(h, "the server refused the WebSocket handshake");
              joined();
            });
          });
        });
  }

  void joined() {
    up.store(true);
    if (ever_connected) note({.kind = LinkNote::Kind::reconnected});
    ever_connected = true;
    told_dropped = false;
    writing.clear();
    write_busy = false;
    ws->text(true);
    write(museum_protocol::write_message(museum_protocol::HelloMessage{
        .role = museum_protocol::role_named(options.role).value_or(museum_protocol::Role::none),
        .token = options.token,
        .seat_key = seat_key}));
    read();
  }

  void read() {
    ws->async_read(buffer, [this](beast::error_code ec, std::size_t) {
      if (ec) return lost(ec, "the connection to the server ended");
      std::string text = beast::buffers_to_string(buffer.data());
      buffer.consume(buffer.size());
      auto parsed = museum_protocol::read_server_message(text);
      // the seat this link took is taken again with its key after a dropped connection
      if (parsed)
        if (const auto* w = std::get_if<Welcome>(&*parsed); w != nullptr && !w->seat_key.empty())
          seat_key = w->seat_key;
      if (parsed) {
        note({.kind = LinkNote::Kind::message, .message = std::move(*parsed), .text = std::move(text)});
      } else {
        log::warn("museum {}: ignored a message from the server: {}", options.role, parsed.error().message);
        note({.kind = LinkNote::Kind::bad_message, .text = parsed.error().message});
      }
      read();
    });
  }

  void write(std::string text) {
    writing.push_back(std::move(text));
    if (!write_busy) write_next();
  }
  void write_next() {
    if (writing.empty() || !ws) {
      write_busy = false;
      return;
    }
    write_busy = true;
    ws->async_write(asio::buffer(writing.front()), [this](beast::error_code ec, std::size_t) {
      if (ec) return;  // the read fails too and reports the drop
      writing.pop_front();
      write_next();
    });
  }

  void lost(beast::error_code ec, const char* what) {
    up.store(false);
    if (stopping.load()) return;
    if (!told_dropped) {
      told_dropped = true;
      note({.kind = LinkNote::Kind::dropped, .text = fmt::format("{}: {}", what, ec.message())});
    }
    if (ws) {
      beast::error_code ignored;
      beast::get_lowest_layer(*ws).socket().close(ignored);
    }
    if (!options.reconnect) return;
    retry_timer.expires_after(std::chrono::duration_cast<std::chrono::steady_clock::duration>(
        std::chrono::duration<double>(options.retry_s)));
    retry_timer.async_wait([this](beast::error_code e) {
      if (!e && !stopping.load()) open();
    });
  }

  void poll() {
    timer.expires_after(kPoll);
    timer.async_wait([this](beast::error_code ec) {
      if (ec) return;
      if (stopping.load()) {
        retry_timer.cancel();
        if (ws) {
          beast::error_code ignored;
          beast::get_lowest_layer(*ws).socket().close(ignored);
        }
        io.stop();
        return;
      }
      flush_backlog();
      std::string text;
      while (outbox.try_pop(text))
        if (up.load()) write(std::move(text));  // a verdict while away is dropped: the station gives it again
      poll();
    });
  }

  void run() {
    open();
    poll();
    io.run();
  }
};

GameLink::GameLink(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

GameLink::~GameLink() { stop(); }

Result<std::unique_ptr<GameLink>> GameLink::connect(const LinkOptions& options) {
  auto address = parse_server_url(options.url);
  if (!address) return address.error();
  auto impl = std::make_unique<Impl>(*address, options);
  Impl* raw = impl.get();
  std::unique_ptr<GameLink> link(new GameLink(std::move(impl)));
  raw->thread = std::thread([raw] { raw->run(); });
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                             std::chrono::duration<double>(options.welcome_s));
  LinkNote n;
  while (std::chrono::steady_clock::now() < deadline) {
    if (!raw->inbox.try_pop(n)) {
      std::this_thread::sleep_for(kPoll);
      continue;
    }
    if (n.kind == LinkNote::Kind::dropped)
      return Error{
          fmt::format("museum server at {}: {} (is `uh museum serve` running there?)", options.url, n.text)};
    if (n.kind != LinkNote::Kind::message) continue;
    if (const auto* e = std::get_if<museum_protocol::ServerError>(&n.message)) {
      if (e->request == "hello" || e->request.empty())
        return Error{fmt::format("museum server at {} refused {}: {}{}", options.url, options.role,
                                 e->message,
                                 e->message.find("token") != std::string::npos ? " (give --token)" : "")};
      continue;
    }
    if (auto* w = std::get_if<Welcome>(&n.message)) {
      link->welcome_ = std::move(*w);
      return link;
    }
  }
  return Error{fmt::format("museum server at {}: no welcome within {:.0f} s of the hello", options.url,
                           options.welcome_s)};
}

bool GameLink::poll(LinkNote& out) { return impl_->inbox.try_pop(out); }

bool GameLink::wait(LinkNote& out, double limit_s) {
  const auto deadline =
      std::chrono::steady_clock::now() +
      std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(limit_s));
  for (;;) {
    if (impl_->inbox.try_pop(out)) return true;
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(1ms);
  }
}

bool GameLink::send(std::string text) { return impl_->outbox.try_push(std::move(text)); }

bool GameLink::connected() const { return impl_->up.load(); }

void GameLink::stop() {
  if (!impl_ || !impl_->thread.joinable()) return;
  impl_->stopping.store(true);
  impl_->thread.join();
}

}  // namespace uh::museum_client
