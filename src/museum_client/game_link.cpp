#include "uh/museum_client/game_link.hpp"

#include <atomic>
#include <chrono>
#include <deque>
#include <thread>

#include <fmt/format.h>

#include "uh/core/log.hpp"
#include "uh/core/spsc_queue.hpp"
#include "uh/net/web_socket_client.hpp"

namespace uh::museum_client {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

constexpr std::size_t kQueueCapacity = 1024;
constexpr auto kPoll = 10ms;  // how long the network thread waits for a message before it looks at
                              // the outgoing queue and stop
constexpr auto kConnectStepLimit = 5s;

Clock::duration seconds(double s) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
}

}  // namespace

Result<ServerAddress> parse_server_url(const std::string& url) {
  auto address =
      net::parse_ws_url(url, {.wrong_form = "the address must be ws://HOST:PORT/ws or http://HOST:PORT/",
                              .example = "ws://127.0.0.1:7780/ws",
                              .default_port = "",
                              .default_path = "/ws",
                              .page_address = true});
  if (!address) return Error{fmt::format("server '{}': {}", url, address.error().message)};
  return address;
}

struct GameLink::Impl {
  Impl(ServerAddress where, LinkOptions link_options)
      : address(std::move(where)), options(std::move(link_options)) {}

  ServerAddress address;
  LinkOptions options;
  // the network thread's
  std::unique_ptr<net::WebSocketClient> client;
  std::deque<LinkNote> backlog;  // notes the owner had no room for yet
  bool ever_connected = false;
  bool told_dropped = false;
  bool retrying = true;              // false: the link stays down after a drop
  Clock::time_point next_attempt{};  // of connecting, after a drop
  std::string seat_key;              // from the first welcome (Phantom's seat)
  std::string received;

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
    auto connected = net::WebSocketClient::connect(
        address, {.name = "the server", .step_limit = kConnectStepLimit, .cancel = &stopping});
    if (!connected) return lost(connected.error().message);
    client = std::move(connected).value();
    joined();
  }

  void joined() {
    up.store(true);
    if (ever_connected) note({.kind = LinkNote::Kind::reconnected});
    ever_connected = true;
    told_dropped = false;
    client->send(museum_protocol::write_message(museum_protocol::HelloMessage{
        .role = museum_protocol::role_named(options.role).value_or(museum_protocol::Role::none),
        .token = options.token,
        .seat_key = seat_key}));
  }

  void take(std::string text) {
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
  }

  void lost(const std::string& why) {
    up.store(false);
    client.reset();
    if (stopping.load()) return;
    if (!told_dropped) {
      told_dropped = true;
      note({.kind = LinkNote::Kind::dropped, .text = why});
    }
    retrying = options.reconnect;
    next_attempt = Clock::now() + seconds(options.retry_s);
  }

  // one turn of the network thread: connect when due, wait a little for a message, send what the
  // owner queued
  void turn() {
    if (!client && retrying && Clock::now() >= next_attempt) open();
    if (client) {
      switch (client->receive(received, kPoll)) {
        case net::WebSocketClient::Received::message:
          take(std::move(received));
          break;
        case net::WebSocketClient::Received::ended:
          lost(fmt::format("the connection to the server ended: {}", client->error().message()));
          break;
        case net::WebSocketClient::Received::nothing:
          break;
      }
    } else {
      std::this_thread::sleep_for(kPoll);
    }
    flush_backlog();
    std::string text;
    while (outbox.try_pop(text))
      if (client) client->send(text);  // a verdict while away is dropped: the station gives it again
  }

  void run() {
    while (!stopping.load()) turn();
    up.store(false);
    client.reset();
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
