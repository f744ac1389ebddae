// Phantom's station against a real museum server over loopback, with the simulated hand as its
// device: a scripted Vive delivers two pieces, the station puts the first in Phantom's hands (its
// packed shape in a running HapticSession), a verdict goes to the server and is scored, the next
// piece follows, and when the server goes away the force goes to zero.

#include "uh/museum_station/station.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "../museum/test_levels.hpp"
#include "test_paths.hpp"
#include "uh/museum_artifacts/artifact.hpp"
#include "uh/museum_service/game_server.hpp"
#include "web_socket_test_client.hpp"

namespace uh::museum_station {
namespace {

using test_support::Client;
using test_support::json;
using Clock = std::chrono::steady_clock;

// Guards against a station that never gets there; not a measurement.
constexpr auto kPatience = std::chrono::seconds(240);

std::optional<json> next_snapshot(Client& c) {
  for (;;) {
    auto m = c.read();
    if (!m) return std::nullopt;
    if ((*m)["type"] == "snapshot") return m;
  }
}

// Vive: to `goal`, then `action` until the snapshot says `done`; false when the connection ended
template <typename Done>
bool walk_and_act(Client& vive, museum::Vec2 goal, const char* action, Done done) {
  for (int snapshots = 0; snapshots < 2000; ++snapshots) {
    const auto s = next_snapshot(vive);
    if (!s) return false;
    if (done(*s)) return true;
    const museum::Vec2 pos{(*s)["vive"]["pos"][0].get<double>(), (*s)["vive"]["pos"][1].get<double>()};
    const museum::Vec2 to = goal - pos;
    const double d = museum::norm(to);
    if (d > 0.3) {
      vive.send({{"type", "move"}, {"move", {to.x / d, to.y / d}}});
    } else {
      vive.send({{"type", "move"}, {"move", {0.0, 0.0}}});
      vive.send({{"type", "action"}, {"action", action}});
    }
  }
  return false;
}

// steps the station's loop (as `uh museum station` does) until `done`, or the patience runs out
template <typename Done>
bool run_station_until(GameLink& link, Station& station, Done done) {
  const auto give_up = Clock::now() + kPatience;
  LinkNote note;
  while (Clock::now() < give_up) {
    while (link.poll(note)) station.handle(note);
    station.frame(0.02);
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

// the open hall with its pieces' forms, as a server needs them
museum::Level hall_with_pieces() {
  museum::Level level = museum::test::open_hall(2);
  level.pieces = museum_artifacts::piece_pairs(level);
  return level;
}

TEST(MuseumStation, FeelsTheDeliveredPieceSendsAVerdictAndDropsTheForceWithTheServer) {
  // two targets, four cases side by side: Vive takes the pieces of cases 0 and 1
  museum::Level level = museum::test::open_hall(4);
  level.pieces = museum_artifacts::piece_pairs(level);
  auto server =
      museum_service::GameServer::start({.host = "127.0.0.1", .port = 0, .level = level, .seed = 5});
  ASSERT_TRUE(server) << server.error().message;
  const std::string url = fmt::format("ws://127.0.0.1:{}/ws", (*server)->port());

  auto link = GameLink::connect({.url = url});
  ASSERT_TRUE(link) << link.error().message;
  EXPECT_EQ((*link)->welcome().role, "phantom");
  EXPECT_EQ((*link)->welcome().level.cases.size(), 4u);
  // a second Phantom is refused by name
  auto second = GameLink::connect({.url = url});
  ASSERT_FALSE(second);
  EXPECT_NE(second.error().message.find("the phantom role is taken"), std::string::npos)
      << second.error().message;

  StationOptions options;
  options.cache_dir = UH_TEST_CACHE_DIR;
  auto station = Station::create((*link)->welcome(), options, std::nullopt, link->get());
  ASSERT_TRUE(station) << station.error().message;

  std::atomic<bool> delivered{false};
  std::atomic<bool> vive_done{false};
  std::thread vive_thread([&] {
    Client vive((*server)->port());
    vive.request({{"type", "hello"}, {"protocol", 1}, {"role", "vive"}}, "welcome");
    const museum::Vec2 at_cases{4.25, 4.5};
    const bool ok = walk_and_act(vive, at_cases, "break",
                                 [](const json& s) { return s["cases"][0]["broken"].get<bool>(); }) &&
                    walk_and_act(vive, at_cases, "break",
                                 [](const json& s) { return s["cases"][1]["broken"].get<bool>(); }) &&
                    walk_and_act(vive, at_cases, "take",
                                 [](const json& s) { return s["vive"]["carried"].size() == 2; }) &&
                    walk_and_act(vive, level.table + museum::Vec2{0.5, 0.0}, "deliver",
                                 [](const json& s) { return s["table"].size() == 2; });
    delivered.store(ok);
    vive_done.store(true);
    // stays until the server goes (a drop would pause the round)
    while (next_snapshot(vive)) {
    }
  });

  // the first piece in Phantom's hands: a running session on its shape, touched by the hand
  const bool felt = run_station_until(**link, **station, [&] {
    controllers::HapticSession* s = (*station)->session();
    return vive_done.load() && s != nullptr && !(*station)->held() && norm(s->state().force_world) > 0.05;
  });
  if (!felt) (*server)->stop();
  ASSERT_TRUE(felt) << "the piece error: " << (*station)->piece_error();
  ASSERT_TRUE(delivered.load());
  const int first = (*station)->item_in_hand();
  ASSERT_GE(first, 0);
  // the piece it renders is the one the server holds to be in Phantom's hands
  const museum::GameState before = (*server)->state();
  ASSERT_GT(before.table_count, 0);
  EXPECT_EQ(before.table[0], first);
  // the form it built is that piece's (the station itself is never told which piece it is)
  const museum::ItemState& held = before.items[static_cast<std::size_t>(first)];
  const museum::PiecePair& pair = level.pieces[static_cast<std::size_t>(held.kind)];
  EXPECT_EQ((*station)->in_hand().form.feature, (held.genuine ? pair.genuine : pair.forgery).feature);
  EXPECT_EQ(
      (*station)->in_hand().kind,
      level.artifact_kinds[static_cast<std::size_t>(before.items[static_cast<std::size_t>(first)].kind)]);
  EXPECT_TRUE((*station)->session()->running());
  EXPECT_EQ((*station)->session()->scene().objects.size(), 1u);
  EXPECT_GT((*station)->session()->scene().objects[0].shape.tree->leaves().size(), 1000u);

  // the verdict: sent, applied by the server's rules and scored
  (*station)->press(StationKey::forgery);
  ASSERT_EQ((*station)->verdicts_sent().size(), 1u);
  EXPECT_EQ((*station)->verdicts_sent()[0].first, first);
  const bool next_in_hand = run_station_until(**link, **station, [&] {
    return (*station)->item_in_hand() >= 0 && (*station)->item_in_hand() != first &&
           (*station)->session() != nullptr && norm((*station)->session()->state().force_world) > 0.05;
  });
  const museum::GameState after = (*server)->state();
  EXPECT_EQ(after.items[static_cast<std::size_t>(first)].place, museum::ItemPlace::rejected);
  EXPECT_EQ(after.score.genuine_rejected + after.score.forgeries_rejected, 1);
  EXPECT_EQ(after.phase, museum::Phase::playing) << "the other target is still to settle";
  ASSERT_TRUE(next_in_hand) << "the piece error: " << (*station)->piece_error();

  // the server goes away: the station hears of it and the force is zero from then on
  (*server)->stop();
  const bool dropped = run_station_until(**link, **station, [&] { return (*station)->held(); });
  ASSERT_TRUE(dropped);
  controllers::HapticSession& session = *(*station)->session();
  // the halt applies from the tick after the one that may be running: the newest state until
  // then may still be the last one with force
  const std::uint64_t halted_at = session.state().haptic_ticks + 2;
  const bool zero_a_while = run_station_until(**link, **station, [&] {
    const controllers::SessionState st = session.state();
    if (st.haptic_ticks > halted_at) {
      EXPECT_EQ(norm(st.force_world), 0.0) << "at tick " << st.haptic_ticks;
    }
    return st.haptic_ticks > halted_at + 200;
  });
  EXPECT_TRUE(zero_a_while);
  EXPECT_TRUE(session.running()) << "held, not stopped: it resumes when the server is back";
  vive_thread.join();
  (*station)->stop();
  EXPECT_EQ((*station)->session(), nullptr) << "stopped (zero force) and gone";
  (*link)->stop();
}

TEST(MuseumStation, SaysWhenTheServerIsUnreachableOrTheAddressIsWrong) {
  // a port nobody listens on: bind one, note it, close it
  std::uint16_t port = 0;
  {
    auto server =
        museum_service::GameServer::start({.host = "127.0.0.1", .port = 0, .level = hall_with_pieces()});
    ASSERT_TRUE(server);
    port = (*server)->port();
  }
  auto link = GameLink::connect({.url = fmt::format("ws://127.0.0.1:{}/ws", port)});
  ASSERT_FALSE(link);
  EXPECT_NE(link.error().message.find("cannot reach the server"), std::string::npos) << link.error().message;
  for (const char* bad : {"ws://127.0.0.1/ws", "ftp://x:1/", "127.0.0.1:99999"}) {
    auto l = GameLink::connect({.url = bad});
    ASSERT_FALSE(l) << bad;
    EXPECT_NE(l.error().message.find(bad), std::string::npos) << l.error().message;
  }
}

TEST(MuseumStation, ABadTokenIsRefusedByName) {
  auto server = museum_service::GameServer::start(
      {.host = "127.0.0.1", .port = 0, .token = "secret", .level = hall_with_pieces()});
  ASSERT_TRUE(server) << server.error().message;
  const std::string url = fmt::format("ws://127.0.0.1:{}/ws", (*server)->port());
  auto wrong = GameLink::connect({.url = url, .token = "guess"});
  ASSERT_FALSE(wrong);
  EXPECT_NE(wrong.error().message.find("the token is wrong"), std::string::npos) << wrong.error().message;
  auto right = GameLink::connect({.url = url, .token = "secret"});
  EXPECT_TRUE(right) << right.error().message;
}

TEST(MuseumStation, ABadDeviceSelectorIsRefusedByName) {
  const Welcome welcome{.role = "phantom", .level = museum::test::open_hall(2), .targets = {"bowl"}};
  auto station = Station::create(welcome, {.device = "no-such-driver:1"}, std::nullopt, nullptr);
  ASSERT_FALSE(station);
  EXPECT_NE(station.error().message.find("no-such-driver"), std::string::npos) << station.error().message;
}

}  // namespace
}  // namespace uh::museum_station
