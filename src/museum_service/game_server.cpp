#include "uh/museum_service/game_server.hpp"

#include <chrono>
#include <deque>
#include <map>
#include <optional>
#include <random>
#include <utility>

#include <fmt/format.h>
#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>

#include "uh/core/log.hpp"
#include "uh/museum/rules.hpp"
#include "uh/museum_protocol/messages.hpp"
#include "uh/museum_protocol/views.hpp"

namespace uh::museum_service {
namespace {

namespace asio = boost::asio;
namespace protocol = museum_protocol;
using nlohmann::json;
using protocol::Action;
using protocol::ActionMessage;
using protocol::HelloMessage;
using protocol::MoveMessage;
using protocol::PingMessage;
using protocol::Role;
using protocol::VerdictMessage;
using net::Peer;
using Clock = std::chrono::steady_clock;

// clients send small messages; anything larger is closed with 1009
constexpr std::size_t kMaxMessageBytes = 64 * 1024;
// A client may fail its hello (a wrong or missing token, Phantom's seat without its key) this
// many times; then it is closed. Across all clients, failed hellos beyond kMaxFailedHellosPerSecond
// close the connection without a check, so that guessing by many connections is as slow.
constexpr int kMaxFailedHellos = 3;
constexpr int kMaxFailedHellosPerSecond = 10;
// Refusals logged per client; the rest are counted (refused_messages()) but not logged.
constexpr int kLoggedRefusalsPerClient = 5;

// 128 random bits in hex: Phantom's seat key.
std::string make_seat_key() {
  std::random_device random;
  std::string key;
  for (int i = 0; i < 4; ++i) key += fmt::format("{:08x}", static_cast<std::uint32_t>(random()));
  return key;
}

// Client text as it may appear in the operator's log: control bytes and anything beyond ASCII
// escaped (no forged lines, no terminal escape sequences), at most `limit` characters.
std::string loggable(std::string_view text, std::size_t limit = 160) {
  std::string out;
  for (const char ch : text) {
    if (out.size() >= limit) {
      out += "...";
      break;
    }
    const auto c = static_cast<unsigned char>(ch);
    if (c >= 0x20 && c < 0x7f && c != '\\')
      out.push_back(ch);
    else
      out += fmt::format("\\x{:02x}", c);
  }
  return out;
}

// At most `lines` log lines per `window`; the ones beyond are counted and reported with the next
// line allowed.
class LogBudget {
 public:
  LogBudget(int lines, Clock::duration window) : lines_(lines), window_(window) {}
  // whether a line may be logged now; `skipped` gets how many were not since the last one
  bool allow(std::uint64_t& skipped) {
    const auto now = Clock::now();
    if (now - window_start_ >= window_) {
      window_start_ = now;
      used_ = 0;
    }
    if (used_ >= lines_) {
      ++skipped_;
      return false;
    }
    ++used_;
    skipped = std::exchange(skipped_, 0);
    return true;
  }

 private:
  int lines_;
  Clock::duration window_;
  Clock::time_point window_start_{};
  int used_ = 0;
  std::uint64_t skipped_ = 0;
};

// the rules catch up at most this many ticks after a stall, then drop the rest (the round's
// time is game time: a stalled server does not eat the players' time)
constexpr int kMaxCatchUpTicks = 5;

// The round and its clients, on the host's network thread: no locks.
class GameHub final : public net::Endpoint {
 public:
  GameHub(asio::io_context& io, const museum::Level& level, std::uint64_t seed, std::string token,
          int snapshot_every, double speed, double resume_delay_s, double seat_hold_s)
      : level_(level),
        resume_delay_(
            std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(resume_delay_s))),
        seat_hold_(std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seat_hold_s))),
        state_(museum::new_game(level, seed)),
        token_(std::move(token)),
        snapshot_every_(snapshot_every),
        tick_(std::chrono::duration_cast<Clock::duration>(
            std::chrono::duration<double>(level.rules.tick_s / speed))),
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
    if (c.failed_hellos >= kMaxFailedHellos) return;  // being closed
    const protocol::ParsedClientMessage m = protocol::read_client_message(text);
    if (!m.body) return refuse(id, c, m.id, m.type, m.error);
    if (!c.greeted && !std::holds_alternative<HelloMessage>(*m.body)) {
      return refuse(id, c, m.id, m.type,
                    fmt::format("send hello first: {{\"type\":\"hello\",\"protocol\":{},\"role\":\"vive\"}}",
                                protocol::kProtocolVersion));
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
    if (role == Role::phantom) phantom_left_at_ = Clock::now();
    if (role == Role::vive || role == Role::phantom) {
      log_players("{} dropped out; the round pauses until it reconnects", to_string(role));
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
    int refusals = 0;
    int failed_hellos = 0;
  };

  void refuse(ClientId id, Client& c, const json& req_id, std::string_view type, const std::string& message) {
    ++refused_;
    // a few per client, and those escaped: a client cannot flood the log nor forge its lines
    if (++c.refusals <= kLoggedRefusalsPerClient)
      log::warn(
          "museum: client {} ({}): refused {}: {}{}", id, c.peer->address(),
          type.empty() ? std::string("a message") : loggable(type), loggable(message),
          c.refusals == kLoggedRefusalsPerClient ? " (further refusals of this client are not logged)" : "");
    c.peer->send(protocol::write_message(
        protocol::ServerError{.id = req_id, .request = std::string(type), .message = message}));
  }

  // a failed hello: refused, and the client closed after a few (or at once when many clients fail)
  void refuse_hello(ClientId id, Client& c, const json& req_id, const std::string& message) {
    refuse(id, c, req_id, "hello", message);
    ++c.failed_hellos;
    ++failed_hellos_this_second_;
    if (c.failed_hellos >= kMaxFailedHellos) c.peer->close(1008, "too many failed hellos");
  }

  // whether hellos are checked now: not for a client being closed after its failures, and not
  // while the second's failures across all clients are used up (the client is closed then)
  bool may_try_hello(Client& c) {
    if (c.failed_hellos >= kMaxFailedHellos) return false;
    const auto now = Clock::now();
    if (now - failed_hellos_second_ >= std::chrono::seconds(1)) {
      failed_hellos_second_ = now;
      failed_hellos_this_second_ = 0;
    }
    if (failed_hellos_this_second_ < kMaxFailedHellosPerSecond) return true;
    c.failed_hellos = kMaxFailedHellos;
    c.peer->close(1008, "too many failed hellos on this server; try again later");
    return false;
  }

  // the join and drop-out lines, bounded however often players reconnect
  template <typename... Args>
  void log_players(fmt::format_string<Args...> format, Args&&... args) {
    std::uint64_t skipped = 0;
    if (!player_log_.allow(skipped)) return;
    const std::string line = fmt::format(format, std::forward<Args>(args)...);
    if (skipped > 0)
      log::info("museum: {} ({} more joins and drop-outs were not logged)", line, skipped);
    else
      log::info("museum: {}", line);
  }

  bool role_connected(Role role) const {
    for (const auto& [id, c] : clients_)
      if (c.role == role) return true;
    return false;
  }

  void handle(ClientId id, Client& c, const json& req_id, const std::string& type, const HelloMessage& h) {
    if (!c.greeted && !may_try_hello(c)) return;
    if (c.greeted)
      return refuse(id, c, req_id, type, fmt::format("already greeted as {}", to_string(c.role)));
    if (h.protocol != protocol::kProtocolVersion)
      return refuse(id, c, req_id, type,
                    fmt::format("protocol {} is not supported; this server speaks {}", h.protocol,
                                protocol::kProtocolVersion));
    if (!token_.empty() && !net::same_token(h.token, token_))
      return refuse_hello(id, c, req_id,
                          h.token.empty() ? "this server needs a token" : "the token is wrong");
    if (h.role != Role::watcher && role_connected(h.role))
      return refuse(id, c, req_id, type,
                    fmt::format("the {} role is taken by another client", to_string(h.role)));
    // Phantom's seat is its station's: while it is held, only the holder of its key takes it again
    const bool same_station =
        !phantom_seat_key_.empty() && net::same_token(h.seat_key, phantom_seat_key_);
    if (h.role == Role::phantom && seat_held() && !same_station)
      return refuse_hello(
          id, c, req_id,
          h.seat_key.empty() ? "the phantom seat is held for the station that took it: a reconnect sends the "
                               "seat_key of its first welcome"
                             : "the seat_key is wrong");
    // a new station (the first, or one after the hold) gets a new key
    if (h.role == Role::phantom && !same_station) phantom_seat_key_ = make_seat_key();
    c.greeted = true;
    c.role = h.role;
    // no seed: a client given it could deal the round itself and know every genuine piece
    protocol::Welcome welcome = protocol::welcome_of(level_, state_, h.role);
    welcome.id = req_id;
    if (h.role == Role::phantom) welcome.seat_key = phantom_seat_key_;
    c.peer->send(protocol::write_message(welcome));
    if (h.role == Role::vive || h.role == Role::phantom) {
      log_players("{} joined ({})", to_string(h.role), c.peer->address());
      update_pause();
    }
    c.peer->send(snapshot());
    if (h.role == Role::phantom) send_in_hands(c);
    if (summary_sent_)
      c.peer->send(protocol::write_message(protocol::summary_of(level_, museum::summarize(level_, state_))));
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
    c.peer->send(protocol::write_message(protocol::Pong{.id = req_id, .tick = state_.tick}));
  }

  // the round plays while both players are connected; after a pause it resumes resume_delay_ after
  // both are back (play_tick() lifts the pause then), the first start at once: a player who
  // reconnects over and over never moves the paused round
  // Phantom's seat is held for its station on a server with a token (where token holders must not
  // take it) for seat_hold_ after the station dropped out; then another may sit down
  bool seat_held() const {
    return !token_.empty() && phantom_left_at_ && Clock::now() - *phantom_left_at_ < seat_hold_;
  }

  void update_pause() {
    const bool both = role_connected(Role::vive) && role_connected(Role::phantom);
    if (!both) {
      state_.paused = true;
      resume_at_.reset();
      return;
    }
    if (!started_) {
      started_ = true;
      state_.paused = false;
      return;
    }
    if (state_.paused && !resume_at_) resume_at_ = Clock::now() + resume_delay_;
  }

  std::string phase() const {
    if (state_.phase == museum::Phase::ended) return "ended";
    if (!started_) return "waiting";
    return state_.paused ? "paused" : "playing";
  }

  std::string snapshot() const {
    return protocol::write_message(protocol::snapshot_of(level_, state_, phase(), role_connected(Role::vive),
                                                         role_connected(Role::phantom)));
  }

  void broadcast(const std::string& text, bool is_state = false) {
    for (auto& [id, c] : clients_)
      if (c.greeted) c.peer->send(text, is_state);
  }
  void broadcast_snapshot() { broadcast(snapshot(), true); }

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
    if (resume_at_ && Clock::now() >= *resume_at_) {
      resume_at_.reset();
      state_.paused = false;
    }
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
      broadcast(protocol::write_message(protocol::GameEvent{events_.list[static_cast<std::size_t>(i)]}));
    if (state_.phase == museum::Phase::ended && !summary_sent_) {
      summary_sent_ = true;
      const museum::RoundSummary summary = museum::summarize(level_, state_);
      log::info("museum: the round ended: {} points", summary.score.points);
      broadcast_snapshot();
      broadcast(protocol::write_message(protocol::summary_of(level_, summary)));
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
    c.peer->send(protocol::write_message(protocol::in_hand_of(level_, state_, state_.table[0])));
  }

  museum::Level level_;
  Clock::duration resume_delay_;
  Clock::duration seat_hold_;
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
  std::optional<Clock::time_point> resume_at_;        // when a paused round plays again
  std::string phantom_seat_key_;                      // given in Phantom's first welcome
  std::optional<Clock::time_point> phantom_left_at_;  // when Phantom's station last dropped out
  Clock::time_point failed_hellos_second_{};
  int failed_hellos_this_second_ = 0;
  LogBudget player_log_{20, std::chrono::minutes(1)};
  bool summary_sent_ = false;
  bool shut_down_ = false;
  std::uint64_t refused_ = 0;
};

}  // namespace

struct GameServer::Impl {
  std::unique_ptr<net::WebSocketHost> host;
  GameHub* hub = nullptr;  // the host's endpoint: the network thread's
};

GameServer::GameServer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

GameServer::~GameServer() { stop(); }

Result<std::unique_ptr<GameServer>> GameServer::start(GameServerOptions options) {
  if (const Status valid = museum::validate(options.level); !valid)
    return Error{"level: " + valid.error().message};
  if (options.level.pieces.empty())
    return Error{
        "level: no pieces: Phantom's station is told the form of each piece it holds "
        "(museum_artifacts::piece_pairs)"};
  if (!(options.snapshot_hz >= 20.0 && options.snapshot_hz <= 30.0))
    return Error{fmt::format("snapshot rate {} Hz is not within 20..30 Hz", options.snapshot_hz)};
  if (!(options.speed >= 0.1 && options.speed <= 20.0))
    return Error{fmt::format("speed {} is not within 0.1..20 (game seconds per second)", options.speed)};
  if (!(options.resume_delay_s >= 0.0 && options.resume_delay_s <= 600.0))
    return Error{fmt::format("resume delay {} s is not within 0..600 s", options.resume_delay_s)};
  if (!(options.seat_hold_s >= 0.0 && options.seat_hold_s <= 3600.0))
    return Error{fmt::format("seat hold {} s is not within 0..3600 s", options.seat_hold_s)};
  // snapshots every n rule ticks: the rate within 20..30 Hz nearest the one asked for
  const double tick_hz = 1.0 / options.level.rules.tick_s;
  const int every = std::max(1, static_cast<int>(std::lround(tick_hz / options.snapshot_hz)));
  auto impl = std::make_unique<Impl>();
  GameHub* hub = nullptr;
  auto host = net::WebSocketHost::start(
      {.host = options.host,
       .port = options.port,
       .has_token = !options.token.empty(),
       .files = std::move(options.files),
       .ws_description = "this is the WebSocket endpoint of the museum heist (docs/museum.md)\n",
       .no_page = "this build of uh has no browser client for the museum\n",
       .program = "uh museum serve"},
      [&](asio::io_context& io) {
        auto made = std::make_unique<GameHub>(io, options.level, options.seed, options.token, every,
                                              options.speed, options.resume_delay_s, options.seat_hold_s);
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
