// `uh museum serve`'s server over real sockets on loopback: scripted Beast clients play Vive and
// Phantom in the messages of docs/museum.md, with latency and loss added on their side.

#include "uh/museum_service/game_server.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <random>
#include <thread>

#include "../museum/test_levels.hpp"
#include "uh/museum_artifacts/artifact.hpp"
#include "uh/museum_protocol/messages.hpp"
#include "web_socket_test_client.hpp"

namespace uh::museum_service {
namespace {

using test_support::Client;
using test_support::json;

json hello_as(const std::string& role, json extra = json::object()) {
  json h = {{"type", "hello"}, {"protocol", 1}, {"role", role}};
  h.update(extra);
  return h;
}

// reads until a snapshot; nullopt when the connection ended
std::optional<json> next_snapshot(Client& c) {
  for (;;) {
    auto m = c.read();
    if (!m) return std::nullopt;
    if ((*m)["type"] == "snapshot") return m;
  }
}

// a round on the open hall: one target, its two pieces side by side, no guards
GameServerOptions open_hall_round(std::uint64_t seed = 3) {
  museum::Level level = museum::test::open_hall(2);
  level.pieces = museum_artifacts::piece_pairs(level);
  return {.host = "127.0.0.1", .port = 0, .level = level, .seed = seed};
}

std::unique_ptr<GameServer> start(GameServerOptions options) {
  auto s = GameServer::start(std::move(options));
  EXPECT_TRUE(s.has_value()) << (s ? "" : s.error().message);
  return s ? std::move(s).value() : nullptr;
}

TEST(MuseumServer, WelcomeCarriesTheLevelAndTheTargets) {
  auto server = start(open_hall_round());
  ASSERT_TRUE(server);
  Client vive(server->port());
  const json w = vive.request(hello_as("vive", {{"id", 7}}), "welcome");
  EXPECT_EQ(w["id"], 7);
  EXPECT_EQ(w["protocol"], museum_protocol::kProtocolVersion);
  EXPECT_EQ(w["role"], "vive");
  EXPECT_EQ(w["level"]["rooms"].size(), 1u);
  EXPECT_EQ(w["level"]["cases"].size(), 2u);
  ASSERT_EQ(w["targets"].size(), 1u);
  EXPECT_FALSE(w.contains("seed")) << "the seed deals the round: with it a client knows every genuine piece";
  const json s = *next_snapshot(vive);
  EXPECT_EQ(s["phase"], "waiting") << "the round waits for Phantom";
  EXPECT_EQ(s["tick"], 0);
  // the snapshot never tells which piece is genuine
  EXPECT_EQ(s.dump().find("genuine"), std::string::npos);
}

TEST(MuseumServer, BadMessagesGetErrorsNamingTheProblemAndTheConnectionStaysUsable) {
  auto server = start(open_hall_round());
  ASSERT_TRUE(server);
  Client c(server->port());
  struct Case {
    std::string text;
    std::string expected;
  };
  const std::vector<Case> before_hello = {
      {"{not json", "not valid JSON"},
      {"[1, 2]", "must be a JSON object"},
      {R"({"id": 1})", "'type' is missing"},
      {R"({"type": "dance"})", "unknown message type 'dance'"},
      {R"({"type": "move", "move": [1, 0]})", "send hello first"},
      {R"({"type": "hello", "protocol": 2, "role": "vive"})", "protocol 2 is not supported"},
      {R"({"type": "hello", "protocol": 1, "role": "guard"})", "'role' is 'guard'"},
      {R"({"type": "hello", "protocol": 1})", "'role' is missing"},
  };
  std::uint64_t refused = 0;
  for (const Case& k : before_hello) {
    c.send_text(k.text);
    const json e = c.expect("error");
    EXPECT_NE(e["message"].get<std::string>().find(k.expected), std::string::npos)
        << k.text << " -> " << e.dump();
    ++refused;
  }
  c.request(hello_as("phantom"), "welcome");
  const std::vector<Case> after_hello = {
      {R"({"type": "move", "move": [1, 0]})", "only vive moves; this client is phantom"},
      {R"({"type": "action", "action": "break"})", "only vive acts"},
      {R"({"type": "verdict", "item": 0, "verdict": "genuine"})", "nothing is on the table"},
      {R"({"type": "verdict", "item": 0, "verdict": "maybe"})", "'verdict' is 'maybe'"},
      {R"({"type": "verdict", "verdict": "genuine"})", "'item' must be the number of the artifact"},
      {R"({"type": "hello", "protocol": 1, "role": "vive"})", "already greeted as phantom"},
  };
  for (const Case& k : after_hello) {
    c.send_text(k.text);
    const json e = c.expect("error");
    EXPECT_NE(e["message"].get<std::string>().find(k.expected), std::string::npos)
        << k.text << " -> " << e.dump();
    ++refused;
  }
  c.send_binary("\x01\x02");
  EXPECT_NE(c.expect("error")["message"].get<std::string>().find("binary frames"), std::string::npos);
  ++refused;
  // still usable
  EXPECT_EQ(c.request({{"type", "ping"}, {"id", "p"}}, "pong")["id"], "p");
  EXPECT_EQ(server->refused_messages(), refused);

  // one Vive at a time; a second one is told so
  Client vive(server->port());
  vive.request(hello_as("vive"), "welcome");
  Client intruder(server->port());
  intruder.send(hello_as("vive"));
  EXPECT_NE(intruder.expect("error")["message"].get<std::string>().find("the vive role is taken"),
            std::string::npos);
  // a bad Vive message inside a vive's own session
  vive.send_text(R"({"type": "move", "move": [1]})");
  EXPECT_NE(vive.expect("error")["message"].get<std::string>().find("'move' must be [x, y]"),
            std::string::npos);
}

TEST(MuseumServer, SnapshotsComeAtTwentyToThirtyHertzOfGameTime) {
  for (const double hz : {20.0, 30.0}) {
    GameServerOptions options = open_hall_round();
    options.snapshot_hz = hz;
    auto server = start(options);
    ASSERT_TRUE(server);
    Client vive(server->port());
    vive.request(hello_as("vive"), "welcome");
    Client phantom(server->port());
    phantom.request(hello_as("phantom"), "welcome");
    // the tick advances between snapshots by 60 Hz / rate (a late network thread catches up)
    std::int64_t last = -1;
    int steps = 0;
    int regular = 0;
    while (steps < 20) {
      const json s = *next_snapshot(vive);
      if (s["phase"] != "playing") continue;
      const std::int64_t tick = s["tick"];
      if (last >= 0) {
        ++steps;
        const std::int64_t expected = hz == 20.0 ? 3 : 2;
        if (tick - last == expected) ++regular;
        EXPECT_EQ((tick - last) % expected, 0) << "snapshot at tick " << tick << " after " << last;
      }
      last = tick;
    }
    // a snapshot not yet written when the next is due is replaced by it (a slow client gets the
    // newest): under load some gaps double, and a quarter regular ones show the rate
    EXPECT_GE(regular, 5) << hz;
  }
  GameServerOptions bad = open_hall_round();
  bad.snapshot_hz = 60.0;
  auto refused = GameServer::start(bad);
  ASSERT_FALSE(refused.has_value());
  EXPECT_NE(refused.error().message.find("snapshot rate 60 Hz is not within 20..30 Hz"), std::string::npos);
  GameServerOptions broken = open_hall_round();
  broken.level.cases.clear();
  refused = GameServer::start(broken);
  ASSERT_FALSE(refused.has_value());
  EXPECT_NE(refused.error().message.find("level: "), std::string::npos);
  GameServerOptions too_fast = open_hall_round();
  too_fast.speed = 50.0;
  refused = GameServer::start(too_fast);
  ASSERT_FALSE(refused.has_value());
  EXPECT_NE(refused.error().message.find("speed 50 is not within 0.1..20"), std::string::npos);
}

// Says `hello` and returns the answer (welcome or error, other messages skipped); while the role is
// still taken by a client that just left (the server has not yet seen its socket close), again.
json hello_when_free(Client& c, const json& hello) {
  for (;;) {
    c.send(hello);
    std::optional<json> m;
    do m = c.read();
    while (m && (*m)["type"] != "welcome" && (*m)["type"] != "error");
    if (!m) return json::object();
    if ((*m)["type"] == "welcome" ||
        (*m)["message"].get<std::string>().find("role is taken by another client") == std::string::npos)
      return *m;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

// Vive and Phantom say hello; returns once the round has played a few ticks.
json play_a_little(Client& vive, Client& phantom) {
  vive.request(hello_as("vive"), "welcome");
  phantom.request(hello_as("phantom"), "welcome");
  json s;
  do s = *next_snapshot(phantom);
  while (s["phase"] != "playing" || s["tick"].get<int>() < 6);
  return s;
}

TEST(MuseumServer, ADroppedPlayerPausesTheRoundAndAReconnectResumesIt) {
  auto server = start(open_hall_round());
  ASSERT_TRUE(server);
  auto vive = std::make_unique<Client>(server->port());
  Client phantom(server->port());
  json s = play_a_little(*vive, phantom);
  // Vive walks east, then drops out
  vive->send({{"type", "move"}, {"move", {1.0, 0.0}}});
  do s = *next_snapshot(phantom);
  while (s["vive"]["pos"][0].get<double>() <= 1.2);
  vive.reset();
  do s = *next_snapshot(phantom);
  while (s["phase"] != "paused");
  EXPECT_FALSE(s["players"]["vive"].get<bool>());
  const std::int64_t paused_tick = s["tick"];
  const double paused_x = s["vive"]["pos"][0];
  const double paused_time = s["time_left_s"];
  for (int i = 0; i < 5; ++i) {
    s = *next_snapshot(phantom);
    EXPECT_EQ(s["phase"], "paused");
    EXPECT_EQ(s["tick"], paused_tick) << "nothing moves, the timer included";
    EXPECT_EQ(s["vive"]["pos"][0], paused_x);
    EXPECT_EQ(s["time_left_s"], paused_time);
  }
  // she comes back standing still; the round resumes
  Client again(server->port());
  again.request(hello_as("vive"), "welcome");
  do s = *next_snapshot(phantom);
  while (s["phase"] != "playing");
  do s = *next_snapshot(phantom);
  while (s["tick"].get<std::int64_t>() < paused_tick + 6);
  EXPECT_EQ(s["vive"]["pos"][0], paused_x) << "a reconnected Vive does not keep walking";
  EXPECT_LT(s["time_left_s"].get<double>(), paused_time);
}

// A player who reconnects over and over never moves a paused round: it resumes a second after both
// players are back (100 reconnects of Vive, each sending a run, moved her 6 cm while the round showed
// paused); the round itself keeps its tick and timer meanwhile.
TEST(MuseumServer, ReconnectingOverAndOverDoesNotMoveAPausedRound) {
  GameServerOptions options = open_hall_round();
  options.resume_delay_s = 600.0;  // longer than the test: the check does not depend on its speed
  auto server = start(options);
  ASSERT_TRUE(server);
  auto vive = std::make_unique<Client>(server->port());
  Client phantom(server->port());
  json s = play_a_little(*vive, phantom);
  vive.reset();
  do s = *next_snapshot(phantom);
  while (s["phase"] != "paused");
  const auto paused_tick = s["tick"].get<std::int64_t>();
  const double paused_x = s["vive"]["pos"][0];
  for (int i = 0; i < 10; ++i) {
    Client again(server->port());
    ASSERT_EQ(hello_when_free(again, hello_as("vive"))["type"], "welcome");
    again.send({{"type", "move"}, {"move", {1.0, 0.0}}, {"run", true}});
    // two snapshots (six ticks of the rules) with her back and running: the round stays paused
    for (int k = 0; k < 2; ++k) {
      const json seen = *next_snapshot(again);
      EXPECT_EQ(seen["phase"], "paused");
      EXPECT_EQ(seen["tick"], paused_tick);
    }
  }
  const museum::GameState state = server->state();
  EXPECT_EQ(state.tick, paused_tick) << "the round did not play";
  EXPECT_EQ(state.vive.pos.x, paused_x) << "Vive did not move";
  EXPECT_TRUE(state.paused);
}

// Phantom's seat is its station's: while it is away nobody else takes it without the seat key of
// its first welcome (which only Phantom was given); with the key, the station comes back.
TEST(MuseumServer, PhantomsSeatIsTakenAgainOnlyWithItsKey) {
  GameServerOptions options = open_hall_round();
  options.token = "s3cret";
  options.seat_hold_s = 3600.0;  // longer than the test: the check does not depend on its speed
  auto server = start(options);
  ASSERT_TRUE(server);
  const json token = {{"token", "s3cret"}};
  Client vive(server->port());
  EXPECT_FALSE(vive.request(hello_as("vive", token), "welcome").contains("seat_key"))
      << "only Phantom's seat has a key";
  std::string key;
  {
    Client phantom(server->port());
    key = phantom.request(hello_as("phantom", token), "welcome")["seat_key"].get<std::string>();
    EXPECT_EQ(key.size(), 32u);
  }
  // a token holder who is not the station
  Client thief(server->port());
  json e = hello_when_free(thief, hello_as("phantom", token));
  EXPECT_NE(e["message"].get<std::string>().find("the phantom seat is held for the station that took it"),
            std::string::npos)
      << e;
  thief.send(hello_as("phantom", {{"token", "s3cret"}, {"seat_key", std::string(32, '0')}}));
  e = thief.expect("error");
  EXPECT_EQ(e["message"], "the seat_key is wrong");
  thief.send(hello_as("phantom", {{"token", "s3cret"}, {"seat_key", "guess"}}));
  thief.expect("error");
  EXPECT_FALSE(thief.read().has_value()) << "closed after three failed hellos";
  Client station(server->port());
  const json back = station.request(hello_as("phantom", {{"token", "s3cret"}, {"seat_key", key}}), "welcome");
  EXPECT_EQ(back["seat_key"], key);
}

// Without a token everyone on the machine may play any role, and after the hold another station
// may sit down (a station that is gone for good does not end the round): it gets a new key.
TEST(MuseumServer, PhantomsSeatIsFreeWithoutATokenAndAfterTheHold) {
  for (const bool with_token : {false, true}) {
    GameServerOptions options = open_hall_round();
    if (with_token) options.token = "s3cret";
    options.seat_hold_s = 0.0;
    auto server = start(options);
    ASSERT_TRUE(server);
    const json token = with_token ? json{{"token", "s3cret"}} : json::object();
    std::string first;
    {
      Client phantom(server->port());
      first = phantom.request(hello_as("phantom", token), "welcome")["seat_key"].get<std::string>();
    }
    Client other(server->port());
    const json welcome = hello_when_free(other, hello_as("phantom", token));
    EXPECT_NE(welcome["seat_key"], first);
  }
}

TEST(MuseumServer, ATokenIsRequiredWhenConfiguredAndOffLoopback) {
  GameServerOptions open = open_hall_round();
  open.host = "0.0.0.0";
  auto refused = GameServer::start(open);
  ASSERT_FALSE(refused.has_value());
  EXPECT_NE(refused.error().message.find("a token is required"), std::string::npos);
  GameServerOptions with_token = open_hall_round();
  with_token.token = "s3cret";
  auto server = start(with_token);
  ASSERT_TRUE(server);
  Client c(server->port());
  c.send(hello_as("vive"));
  EXPECT_NE(c.expect("error")["message"].get<std::string>().find("needs a token"), std::string::npos);
  c.send(hello_as("vive", {{"token", "wrong"}}));
  EXPECT_NE(c.expect("error")["message"].get<std::string>().find("the token is wrong"), std::string::npos);
  c.request(hello_as("vive", {{"token", "s3cret"}}), "welcome");
}

// A network that delays each message by up to `max_delay` and loses `loss` of them (client side:
// the kernel's loopback neither delays nor loses, and tc needs privileges the tests do not have).
class LossyLink {
 public:
  LossyLink(std::uint32_t seed, std::chrono::milliseconds max_delay, double loss)
      : rng_(seed), delay_(0, static_cast<int>(max_delay.count())), loss_(loss) {}
  // sends unless lost, after the delay; returns whether it was sent
  bool send(Client& c, const json& m) {
    std::this_thread::sleep_for(std::chrono::milliseconds(delay_(rng_)));
    if (std::uniform_real_distribution<double>(0.0, 1.0)(rng_) < loss_) return false;
    c.send(m);
    return true;
  }

 private:
  std::mt19937 rng_;
  std::uniform_int_distribution<int> delay_;
  double loss_;
};

museum::Vec2 pos_of(const json& v) { return {v[0].get<double>(), v[1].get<double>()}; }

// Vive's script: run to `goal` (within 0.25 m), steering from the snapshots; false if the round
// ended or the connection closed first
// and standing still there (a lost stop is sent again)
bool run_to(Client& c, LossyLink& link, museum::Vec2 goal) {
  std::optional<museum::Vec2> last;
  for (;;) {
    const auto s = next_snapshot(c);
    if (!s || (*s)["phase"] == "ended") return false;
    const museum::Vec2 pos = pos_of((*s)["vive"]["pos"]);
    const museum::Vec2 to = goal - pos;
    const double d = museum::norm(to);
    if (d < 0.25) {
      if (last && *last == pos) return true;
      link.send(c, {{"type", "move"}, {"move", {0.0, 0.0}}});
    } else {
      // walk the last metre so that a late stop does not overshoot by much
      link.send(c, {{"type", "move"}, {"move", {to.x / d, to.y / d}}, {"run", d > 1.0}});
    }
    last = pos;
  }
}

// repeats an action until the snapshots show `done`, or the round ends
template <typename Done>
bool act_until(Client& c, LossyLink& link, const std::string& action, Done done) {
  for (int tries = 0; tries < 200; ++tries) {
    link.send(c, {{"type", "action"}, {"action", action}});
    for (int k = 0; k < 3; ++k) {
      const auto s = next_snapshot(c);
      if (!s || (*s)["phase"] == "ended") return false;
      if (done(*s)) return true;
    }
  }
  return false;
}

TEST(MuseumServer, ScriptedPlayersFinishARoundThroughLatencyAndLoss) {
  const GameServerOptions options = open_hall_round(11);
  const museum::Level& level = options.level;
  auto server = start(options);
  ASSERT_TRUE(server);
  json summary;                             // written by Phantom's thread, read after the join
  std::vector<json> in_hands;               // the same
  std::vector<json> phantom_heard;          // the same: every message before the summary
  std::atomic<bool> summary_arrived{false};  // what Vive's loop may look at meanwhile
  std::thread phantom_thread([&] {
    Client phantom(server->port());
    phantom.request(hello_as("phantom"), "welcome");
    LossyLink link(2, std::chrono::milliseconds(60), 0.25);
    // keeps the first piece it is handed, puts the second aside; a lost verdict is given again
    // (a duplicate or a late one names its item, so the server refuses it and says so)
    std::vector<int> seen;
    for (;;) {
      const auto m = phantom.read();
      if (!m) return;
      if ((*m)["type"] == "summary") {
        summary = *m;
        summary_arrived.store(true, std::memory_order_release);
        return;
      }
      phantom_heard.push_back(*m);
      if ((*m)["type"] == "in_hands") in_hands.push_back(*m);
      if ((*m)["type"] != "snapshot" || (*m)["table"].empty()) continue;
      const int item = (*m)["table"][0]["item"];
      if (std::find(seen.begin(), seen.end(), item) == seen.end()) seen.push_back(item);
      const bool first = seen.front() == item;
      link.send(phantom, {{"type", "verdict"}, {"item", item}, {"verdict", first ? "genuine" : "forgery"}});
    }
  });
  const bool delivered = [&] {
    Client vive(server->port());
    vive.request(hello_as("vive"), "welcome");
    LossyLink link(1, std::chrono::milliseconds(60), 0.25);
    const museum::Vec2 between = (level.cases[0].pos + level.cases[1].pos) * 0.5 - museum::Vec2{0.0, 0.5};
    if (!run_to(vive, link, between)) return false;
    for (int c = 0; c < 2; ++c) {
      if (!act_until(vive, link, "break", [&](const json& s) { return s["cases"][c]["broken"].get<bool>(); }))
        return false;
    }
    if (!act_until(vive, link, "take", [](const json& s) { return s["vive"]["carried"].size() == 2; }))
      return false;
    // one more take is refused by the rules (two at most), not by a crash
    link.send(vive, {{"type", "action"}, {"action", "take"}});
    if (!run_to(vive, link, level.table + museum::Vec2{0.5, 0.0})) return false;
    // the round may end (both verdicts given) before the last snapshot shows empty hands
    act_until(vive, link, "deliver", [](const json& s) { return s["vive"]["carried"].empty(); });
    // stays connected until the round ends (a drop would pause it); never told what Phantom holds
    while (!summary_arrived.load(std::memory_order_acquire)) {
      const auto m = vive.read();
      if (!m) break;
      if ((*m)["type"] == "in_hands") ADD_FAILURE() << "only Phantom is told which piece it holds";
    }
    return true;
  }();
  // a failed script: stopping the server ends Phantom's thread too
  if (!delivered) server->stop();
  phantom_thread.join();
  ASSERT_TRUE(delivered);
  ASSERT_FALSE(summary.is_null());
  EXPECT_TRUE(summary["ended_early"].get<bool>());
  const json& score = summary["score"];
  EXPECT_EQ(score["genuine_kept"].get<int>() + score["forgeries_kept"].get<int>(), 1);
  EXPECT_EQ(score["genuine_rejected"].get<int>() + score["forgeries_rejected"].get<int>(), 1);
  const int base =
      score["genuine_kept"].get<int>() == 1 ? level.rules.genuine_points : -level.rules.forgery_penalty;
  EXPECT_EQ(score["points"].get<int>(), base + score["time_bonus"].get<int>());
  EXPECT_GT(score["time_bonus"].get<int>(), 0);
  // the server's own state agrees with what the clients were told
  const museum::GameState end = server->state();
  EXPECT_EQ(end.phase, museum::Phase::ended);
  EXPECT_EQ(end.score.points, score["points"].get<int>());
  // Phantom was told each piece as it came into its hands: the two delivered, each as it is
  ASSERT_EQ(in_hands.size(), 2u);
  EXPECT_NE(in_hands[0]["item"], in_hands[1]["item"]);
  for (const json& h : in_hands) {
    const museum::ItemState& item = end.items[h["item"].get<std::size_t>()];
    EXPECT_EQ(h["kind"], level.artifact_kinds[static_cast<std::size_t>(item.kind)]);
    // the form of the piece the server holds it to be, and no word of which piece that is
    const museum::PiecePair& pair = level.pieces[static_cast<std::size_t>(item.kind)];
    EXPECT_EQ(h["form"]["feature"].get<double>(), (item.genuine ? pair.genuine : pair.forgery).feature);
    EXPECT_FALSE(h.contains("piece")) << h.dump();
    EXPECT_EQ(h.dump().find("genuine"), std::string::npos) << h.dump();
    EXPECT_EQ(h.dump().find("forgery"), std::string::npos) << h.dump();
  }
  // one genuine piece and its forgery came: told in the same fields
  EXPECT_EQ(in_hands[0]["form"].size(), in_hands[1]["form"].size());
  // before the summary, nothing Phantom was told names a piece genuine or forged (but its own verdicts)
  for (const json& m : phantom_heard) {
    if (m["type"] == "event" && m["event"] == "verdict") continue;
    EXPECT_EQ(m.dump().find("genuine"), std::string::npos) << m.dump();
    EXPECT_EQ(m.dump().find("forgery"), std::string::npos) << m.dump();
  }
}

}  // namespace
}  // namespace uh::museum_service
