#include "uh/museum_service/game_server.hpp"

#include <chrono>
#include <deque>
#include <map>
#include <optional>
#include <utility>

#include <fmt/format.h>
#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>

#include "game_messages.hpp"
#include "uh/core/log.hpp"
#include "uh/museum/rules.hpp"

namespace uh::museum_service {
namespace {

namespace asio = boost::asio;
using service::Peer;
using Clock = std::chrono::steady_clock;

// clients send small messages; anything larger is closed with 1009
constexpr std::size_t kMaxMessageBytes = 64 * 1024;
// the rules catch up at most this many ticks after a stall, then drop the rest (the round's
// time is game time: a stalled server does not eat the players' time)
constexpr int kMaxCatchUpTicks = 5;

// The round and its clients, on the host's network thread: no locks.
class GameHub final : public service::Endpoint {
 public:
  GameHub(asio::io_context& io, const museum::Level& level, std::uint64_t seed, std::string token,
          int snapshot_every, double speed)
      : level_(level),
        state_(museum::new_game(level, seed)),
        token_(std::move(token)),
        snapshot_every_(snapshot_every),
        tick_(std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(level.rules.tick_s / speed))),
        timer_(io) {
    state_.paused = true;
    next_tick_ = Clock::now();
    schedule();
  }

  ClientId connect(Peer& peer) override {
    const ClientId id = next_id_++;
    clients_[id].peer = &peer;
    return id;
  }

  void receive(ClientId id, std::string_view text) override {
    const auto it = clients_.find(id);
    if (it == clients_.end() || shut_down_) return;
    Client& c = it->second;
    const ParsedMessage m = parse_message(text);
    if (!m.body) return refuse(id, c, m.id, m.type, m.error);
    if (!c.greeted && !std::holds_alternative<HelloMessage>(*m.body)) {
      return refuse(id, c, m.id, m.type,
                    fmt::format("send hello first: {{\"type\":\"hello\",\"protocol\":{},\"role\":\"vive\"}}",
                                kGameProtocolVersion));
    }
    std::visit([&](const auto& body) { handle(id, c, m.id, m.type, body); }, *m.body);
  }

  void receive_binary(ClientId id, std::span<const std::byte>) override {
    const auto it = clients_.find(id);
    if (it == clients_.end() || shut_down_) return;
    refuse(id, it->second, nullptr, "", "binary frames are not part of the museum protocol; send JSON text");
  }

  std::size_t message_limit(ClientId) const override { return kMaxMessageBytes; }

  void disconnect(ClientId id) override {
    const auto it = clients_.find(id);
    if (it == clients_.end()) return;
    const Role role = it->second.role;
    clients_.erase(it);
    if (role == Role::vive) {
      // she stands still when she comes back
      move_ = {};
      actions_.clear();
    }
    if (role == Role::vive || role == Role::phantom) {
      log::info("museum: {} dropped out; the round pauses until it reconnects", to_string(role));
      update_pause();
      broadcast_snapshot();
    }
  }

  void shutdown() override {
    if (shut_down_) return;
    shut_down_ = true;
    timer_.cancel();
    for (auto& [id, c] : clients_) c.peer->close(1001, "the server is stopping");
  }

  const museum::GameState& state() const { return state_; }
  std::uint64_t refused() const { return refused_; }

 private:
  struct Client {
    Peer* peer = nullptr;
    bool greeted = false;
    Role role = Role::none;
  };

  void refuse(ClientId id, Client& c, const json& req_id, std::string_view type, const std::string& message) {
    ++refused_;
    log::warn("museum: client {}: refused {}: {}", id, type.empty() ? "a message" : std::string(type),
              message);
    c.peer->send(error_message(req_id, type, message).dump());
  }

  bool role_connected(Role role) const {
    for (const auto& [id, c] : clients_)
      if (c.role == role) return true;
    return false;
  }

  void handle(ClientId id, Client& c, const json& req_id, const std::string& type, const HelloMessage& h) {
    if (c.greeted)
      return refuse(id, c, req_id, type, fmt::format("already greeted as {}", to_string(c.role)));
    if (h.protocol != kGameProtocolVersion)
      return refuse(id, c, req_id, type,
                    fmt::format("protocol {} is not supported; this server speaks {}", h.protocol,
                                kGameProtocolVersion));
    if (!token_.empty() && !service::same_token(h.token, token_))
      return refuse(id, c, req_id, type,
                    h.token.empty() ? "this server needs a token" : "the token is wrong");
    if (h.role != Role::watcher && role_connected(h.role))
      return refuse(id, c, req_id, type,
                    fmt::format("the {} role is taken by another client", to_string(h.role)));
    c.greeted = true;
    c.role = h.role;
    json targets = json::array();
    for (int t = 0; t < state_.target_count; ++t)
      targets.push_back(
          level_.artifact_kinds[static_cast<std::size_t>(state_.target_kinds[static_cast<std::size_t>(t)])]);
    // no seed: a client given it could deal the round itself and know every genuine piece
    c.peer->send(json{
        {"type", "welcome"},
        {"id", req_id},
        {"protocol", kGameProtocolVersion},
        {"role", to_string(h.role)},
        {"level", level_json(level_)},
        {"targets",
         targets}}.dump());
    if (h.role == Role::vive || h.role == Role::phantom) {
      log::info("museum: {} joined", to_string(h.role));
      update_pause();
    }
    c.peer->send(snapshot().dump());
    if (h.role == Role::phantom) send_in_hands(c);
    if (summary_sent_) c.peer->send(summary_json(level_, museum::summarize(level_, state_)).dump());
  }

  void handle(ClientId id, Client& c, const json& req_id, const std::string& type, const MoveMessage& m) {
    if (c.role != Role::vive)
      return refuse(id, c, req_id, type,
                    fmt::format("only vive moves; this client is {}", to_string(c.role)));
    move_ = m;
  }

  void handle(ClientId id, Client& c, const json& req_id, const std::string& type, const ActionMessage& a) {
    if (c.role != Role::vive)
      return refuse(id, c, req_id, type, fmt::format("only vive acts; this client is {}", to_string(c.role)));
    if (actions_.size() >= 16)
      return refuse(id, c, req_id, type, "too many actions waiting for the next ticks");
    actions_.push_back(a.action);
  }

  void handle(ClientId id, Client& c, const json& req_id, const std::string& type, const VerdictMessage& v) {
    if (c.role != Role::phantom)
      return refuse(id, c, req_id, type,
                    fmt::format("only phantom gives verdicts; this client is {}", to_string(c.role)));
    if (state_.table_count == 0) return refuse(id, c, req_id, type, "nothing is on the table to judge");
    if (v.item != state_.table[0])
      return refuse(
          id, c, req_id, type,
          fmt::format("item {} is not the artifact in Phantom's hands; item {} is", v.item, state_.table[0]));
    if (verdict_) return refuse(id, c, req_id, type, fmt::format("item {} already has a verdict", v.item));
    verdict_ = v.verdict;
  }

  void handle(ClientId, Client& c, const json& req_id, const std::string&, const PingMessage&) {
    c.peer->send(json{{"type", "pong"}, {"id", req_id}, {"tick", state_.tick}}.dump());
  }

  void update_pause() {
    const bool both = role_connected(Role::vive) && role_connected(Role::phantom);
    if (both) started_ = true;
    state_.paused = !both;
  }

  std::string phase() const {
    if (state_.phase == museum::Phase::ended) return "ended";
    if (!started_) return "waiting";
    return state_.paused ? "paused" : "playing";
  }

  json snapshot() const {
    return snapshot_json(level_, state_, phase(), role_connected(Role::vive), role_connected(Role::phantom));
  }

  void broadcast(const std::string& text, bool is_state = false) {
    for (auto& [id, c] : clients_)
      if (c.greeted) c.peer->send(text, is_state);
  }
  void broadcast_snapshot() { broadcast(snapshot().dump(), true); }

  void schedule() {
    timer_.expires_at(next_tick_);
    timer_.async_wait([this](const boost::system::error_code& ec) {
      if (ec || shut_down_) return;
      const auto now = Clock::now();
      int ticks = 0;
      while (next_tick_ <= now && ticks < kMaxCatchUpTicks) {
        play_tick();
        next_tick_ += tick_;
        ++ticks;
      }
      if (next_tick_ <= now) next_tick_ = now + tick_;
      schedule();
    });
  }

  void play_tick() {
    museum::TickInput input;
    if (!state_.paused) {
      input.vive.move = move_.move;
      input.vive.run = move_.run;
      if (!actions_.empty()) {
        const Action a = actions_.front();
        actions_.pop_front();
        input.vive.break_case = a == Action::break_case;
        input.vive.take = a == Action::take;
        input.vive.deliver = a == Action::deliver;
      }
      // the verdict was checked against the first item on the table, which only a verdict changes
      input.verdict = std::exchange(verdict_, std::nullopt).value_or(museum::Verdict::none);
    }
    museum::step(level_, state_, input, events_);
    for (int i = 0; i < events_.count; ++i)
      broadcast(event_json(events_.list[static_cast<std::size_t>(i)]).dump());
    if (state_.phase == museum::Phase::ended && !summary_sent_) {
      summary_sent_ = true;
      const museum::RoundSummary summary = museum::summarize(level_, state_);
      log::info("museum: the round ended: {} points", summary.score.points);
      broadcast_snapshot();
      broadcast(summary_json(level_, summary).dump());
    }
    if (++server_ticks_ % snapshot_every_ == 0) broadcast_snapshot();
    const int front = state_.table_count > 0 ? state_.table[0] : -1;
    if (front != in_hands_) {
      in_hands_ = front;
      for (auto& [id, c] : clients_)
        if (c.role == Role::phantom) send_in_hands(c);
    }
  }

  // the artifact now in Phantom's hands, to Phantom only (nothing when the table is empty)
  void send_in_hands(Client& c) {
    if (state_.table_count == 0 || state_.phase == museum::Phase::ended) return;
    c.peer->send(in_hands_json(level_, state_, state_.table[0]).dump());
  }

  museum::Level level_;
  museum::GameState state_;
  std::string token_;
  int snapshot_every_;
  Clock::duration tick_;  // of the wall clock: the rules' tick over the round's speed
  int in_hands_ = -1;     // the item Phantom was last told it holds
  asio::steady_timer timer_;
  Clock::time_point next_tick_;
  std::int64_t server_ticks_ = 0;
  std::map<ClientId, Client> clients_;
  ClientId next_id_ = 1;
  MoveMessage move_{};
  std::deque<Action> actions_;
  std::optional<museum::Verdict> verdict_;  // for the first item on the table, at the next tick
  museum::Events events_;
  bool started_ = false;
  bool summary_sent_ = false;
  bool shut_down_ = false;
  std::uint64_t refused_ = 0;
};

}  // namespace

struct GameServer::Impl {
  std::unique_ptr<service::WebSocketHost> host;
  GameHub* hub = nullptr;  // the host's endpoint: the network thread's
};

GameServer::GameServer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

GameServer::~GameServer() { stop(); }

Result<std::unique_ptr<GameServer>> GameServer::start(GameServerOptions options) {
  if (const Status valid = museum::validate(options.level); !valid)
    return Error{"level: " + valid.error().message};
  if (!(options.snapshot_hz >= 20.0 && options.snapshot_hz <= 30.0))
    return Error{fmt::format("snapshot rate {} Hz is not within 20..30 Hz", options.snapshot_hz)};
  if (!(options.speed >= 0.1 && options.speed <= 20.0))
    return Error{fmt::format("speed {} is not within 0.1..20 (game seconds per second)", options.speed)};
  // snapshots every n rule ticks: the rate within 20..30 Hz nearest the one asked for
  const double tick_hz = 1.0 / options.level.rules.tick_s;
  const int every = std::max(1, static_cast<int>(std::lround(tick_hz / options.snapshot_hz)));
  auto impl = std::make_unique<Impl>();
  GameHub* hub = nullptr;
  auto host = service::WebSocketHost::start(
      {.host = options.host,
       .port = options.port,
       .has_token = !options.token.empty(),
       .files = std::move(options.files),
       .ws_description = "this is the WebSocket endpoint of the museum heist (docs/museum.md)\n",
       .no_page = "this build of uh has no browser client for the museum\n",
       .program = "uh museum serve"},
      [&](asio::io_context& io) {
        auto made = std::make_unique<GameHub>(io, options.level, options.seed, options.token, every,
                                              options.speed);
        hub = made.get();
        return made;
      });
  if (!host) return host.error();
  impl->host = std::move(host).value();
  impl->hub = hub;
  return std::unique_ptr<GameServer>(new GameServer(std::move(impl)));
}

std::uint16_t GameServer::port() const { return impl_->host->port(); }

std::string GameServer::url() const { return impl_->host->url(); }

museum::GameState GameServer::state() {
  museum::GameState copy;
  impl_->host->run_on_network_thread([&] { copy = impl_->hub->state(); });
  return copy;
}

std::uint64_t GameServer::refused_messages() {
  std::uint64_t n = 0;
  impl_->host->run_on_network_thread([&] { n = impl_->hub->refused(); });
  return n;
}

void GameServer::stop() {
  if (impl_ && impl_->host) impl_->host->stop();
}

}  // namespace uh::museum_service
