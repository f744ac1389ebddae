// uh museum play --bots [--seed N] [--level easy|hard] [--minutes M] [--speed S] [--json]
// uh museum play --bot vive|phantom --server URL
//
// A round with the automated players of uh::museum_players (bot_rounds.hpp) as real clients of the
// game server over loopback WebSocket: `--bots` starts a server and both; `--bot` joins a server in
// one role (Vive in a browser against the automated Phantom). This file parses the arguments and
// prints what the watcher sees.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "uh/core/log.hpp"
#include "uh/museum/cues.hpp"
#include "uh/museum/level.hpp"
#include "uh/museum_artifacts/artifact.hpp"
#include "uh/museum_client/game_link.hpp"
#include "uh/museum_players/bot_rounds.hpp"
#include "uh/museum_players/vive_view.hpp"
#include "uh/museum_service/game_server.hpp"

namespace uh::cli {
namespace {

using museum_players::BlindVerdict;
using museum_protocol::GameEvent;
using museum_protocol::Snapshot;
using museum_protocol::Summary;
using museum_protocol::Welcome;
using nlohmann::json;

// One bot's round on the server at `url`; the blind bot's verdicts are collected for the report.
Status play_bot(const std::string& role, const std::string& url, std::uint64_t seed,
                std::vector<BlindVerdict>& verdicts, std::mutex& verdicts_mutex, bool announce) {
  if (role != "phantom") return museum_players::play_vive(url);
  return museum_players::play_phantom({.url = url,
                                       .seed = seed,
                                       .seated =
                                           [announce] {
                                             if (!announce) return;
                                             std::printf("uh museum play: Phantom is at the table\n");
                                             std::fflush(stdout);
                                           },
                                       .judged =
                                           [&](const BlindVerdict& v) {
                                             const std::lock_guard lock(verdicts_mutex);
                                             verdicts.push_back(v);
                                           }});
}

struct MuseumPlayArgs {
  bool bots = false;
  std::string bot;     // with --server: vive or phantom
  std::string server;  // ws://HOST:PORT/ws or http://HOST:PORT/
  std::uint64_t seed = 1;
  std::string level = "easy";
  double minutes = 0.0;
  double speed = 1.0;
  bool json = false;
};

std::string clock_of(double seconds_left) {
  const int s = static_cast<int>(std::ceil(std::max(0.0, seconds_left)));
  return fmt::format("{}:{:02}", s / 60, s % 60);
}

// One bot joining a running server (e.g. Phantom against Vive in a browser).
int museum_play_one(const MuseumPlayArgs& args) {
  if (auto address = museum_client::parse_server_url(args.server); !address)
    return fail("--" + address.error().message);
  std::printf("uh museum play: the %s bot joins %s\n", args.bot.c_str(), args.server.c_str());
  std::fflush(stdout);
  std::vector<BlindVerdict> verdicts;
  std::mutex verdicts_mutex;
  const Status played = play_bot(args.bot, args.server, args.seed, verdicts, verdicts_mutex, true);
  if (!played) return fail(played.error().message);
  for (const BlindVerdict& v : verdicts)
    std::printf("uh museum play: judged the %s (item %d): %s\n", v.kind.c_str(), v.item,
                museum_players::to_string(v.judgement.verdict));
  std::printf("uh museum play: the round ended\n");
  return 0;
}

json verdict_json(const BlindVerdict& v) {
  json evidence = json::array();
  for (const auto& f : v.judgement.evidence) evidence.push_back(evidence_json(f));
  return {{"item", v.item},
          {"kind", v.kind},
          {"verdict", museum_players::to_string(v.judgement.verdict)},
          {"simulated_s", v.simulated_s},
          {"evidence", evidence}};
}

// What the watcher saw of a round: its summary (as parsed and as the server wrote it) and how
// many events of each kind there were. With `print`, each event's caption as it comes.
struct WatchedRound {
  std::optional<Summary> summary;
  std::string summary_text;
  json event_counts = json::object();
};

WatchedRound watch_round(museum_client::GameLink& watcher, const museum::Level& level, bool print) {
  WatchedRound round;
  const Welcome& welcome = watcher.welcome();
  double time_left = level.rules.round_s;
  museum_players::ViveView seen(level);  // the round as the watcher sees it: names the pieces in the lines
  for (;;) {
    auto note = museum_players::next_message(watcher);
    if (!note) break;
    if (const auto* s = std::get_if<Snapshot>(&note->message)) {
      time_left = s->time_left_s;
      seen.update(*s, welcome.targets);
    }
    if (const auto* e = std::get_if<GameEvent>(&note->message)) {
      const std::string name = museum::to_string(e->event.type);
      round.event_counts[name] = round.event_counts.value(name, 0) + 1;
      if (e->event.type == museum::EventType::guard_heard) seen.heard(e->event);
      if (print)
        std::printf("[%s left] %s\n", clock_of(time_left).c_str(),
                    museum::describe(e->event, level, seen.state()).caption.c_str());
    }
    if (const auto* s = std::get_if<Summary>(&note->message)) {
      round.summary = *s;
      round.summary_text = std::move(note->text);
      break;
    }
    std::fflush(stdout);
  }
  return round;
}

void print_round_json(const MuseumPlayArgs& args, const WatchedRound& round, const std::vector<BlindVerdict>& verdicts,
                      double wall_s) {
  json out{{"level", args.level},
           {"seed", args.seed},
           {"speed", args.speed},
           {"wall_s", wall_s},
           {"summary", json::parse(round.summary_text, nullptr, false)},  // the link parsed it already
           {"events", round.event_counts},
           {"verdicts", json::array()}};
  for (const BlindVerdict& v : verdicts) out["verdicts"].push_back(verdict_json(v));
  std::printf("%s\n", out.dump(2).c_str());
}

void print_round(const Summary& summary, const std::vector<BlindVerdict>& verdicts, double wall_s) {
  std::printf("uh museum play: the round ended%s after %.0f s of game time (%.0f s on the clock)\n",
              summary.ended_early ? " early, every target settled," : "", summary.seconds_played, wall_s);
  for (const museum_protocol::TargetView& t : summary.targets)
    std::printf("  %-8s genuine: %-8s forgery: %s\n", t.kind.c_str(), t.genuine.c_str(), t.forgery.c_str());
  for (const BlindVerdict& v : verdicts) {
    const auto& e = v.judgement.evidence;
    std::printf("  Phantom on the %s (item %d): %s, from %.0f s of touch%s\n", v.kind.c_str(), v.item,
                museum_players::to_string(v.judgement.verdict), v.simulated_s,
                e.empty() ? ""
                          : fmt::format(" (most telling: {} {:.2f} {} against {:.2f})", e.front().feature,
                                        e.front().difference, e.front().unit, e.front().threshold)
                                .c_str());
  }
  std::printf(
      "score %d: %d genuine kept, %d forgeries kept, %d genuine put aside, %d forgeries put aside, "
      "time bonus %d; caught %d times\n",
      summary.points, summary.genuine_kept, summary.forgeries_kept, summary.genuine_rejected,
      summary.forgeries_rejected, summary.time_bonus, summary.times_caught);
}

int museum_play_bots(const MuseumPlayArgs& args) {
  museum::Level level =
      museum::make_level(args.level == "hard" ? museum::Difficulty::hard : museum::Difficulty::easy);
  if (args.minutes > 0.0) level.rules.round_s = args.minutes * 60.0;
  level.pieces = museum_artifacts::piece_pairs(level);
  // the watcher below prints what happens; the server's own notes would repeat it (or break the JSON)
  log::set_level(args.json ? log::Level::error : log::Level::warn);
  auto server = museum_service::GameServer::start(
      {.host = "127.0.0.1", .port = 0, .level = level, .seed = args.seed, .speed = args.speed});
  if (!server) return fail(server.error().message);
  const std::uint16_t port = (*server)->port();
  const auto started = std::chrono::steady_clock::now();
  if (!args.json)
    std::printf(
        "uh museum play: %s level, seed %llu, %.1f min round at %gx; the bots join ws://127.0.0.1:%u/ws\n",
        args.level.c_str(), static_cast<unsigned long long>(args.seed), level.rules.round_s / 60.0,
        args.speed, port);
  std::fflush(stdout);

  // the watcher: what is printed
  const std::string url = fmt::format("ws://127.0.0.1:{}/ws", port);
  auto watcher = museum_players::join_as_bot(url, "watcher");
  if (!watcher) return fail(watcher.error().message);

  std::vector<BlindVerdict> verdicts;
  std::mutex verdicts_mutex;
  std::mutex failure_mutex;
  std::string failure;  // the first bot's error
  const auto run_bot = [&](const std::string& role) {
    const Status played = play_bot(role, url, args.seed, verdicts, verdicts_mutex, !args.json);
    if (!played) {
      {
        const std::lock_guard lock(failure_mutex);
        if (failure.empty()) failure = "the " + role + " bot: " + played.error().message;
      }
      (*server)->stop();  // ends the watcher and the other bot
    }
  };
  std::thread vive([&] { run_bot("vive"); });
  std::thread phantom([&] { run_bot("phantom"); });

  const WatchedRound round = watch_round(**watcher, level, !args.json);
  vive.join();
  phantom.join();
  (*watcher)->stop();
  (*server)->stop();
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  if (!failure.empty()) return fail(failure);
  if (!round.summary) return fail("the round did not end: the server closed the connection first");

  if (args.json)
    print_round_json(args, round, verdicts, wall_s);
  else
    print_round(*round.summary, verdicts, wall_s);
  return 0;
}

}  // namespace

void add_museum_play_command(CLI::App& museum, CommandRunner& runner) {
  static MuseumPlayArgs args;
  auto* p = museum.add_subcommand("play",
                                  "play a round with automated players: both (--bots), or one joining a "
                                  "server (--bot ROLE --server URL)");
  auto* bots = p->add_flag("--bots", args.bots, "start a server and play a whole round with both bots");
  auto* bot = p->add_option("--bot", args.bot, "join --server as this bot: vive or phantom")
                  ->check(CLI::IsMember({"vive", "phantom"}));
  auto* server =
      p->add_option("--server", args.server, "the game server to join, e.g. ws://127.0.0.1:7780/ws");
  bot->needs(server);
  server->needs(bot);
  bots->excludes(bot);
  p->add_option("--seed", args.seed, "deals the round (--bots) and the blind bot's touch")->default_val(1);
  auto* level = p->add_option("--level", args.level, "easy or hard")
                    ->default_val("easy")
                    ->check(CLI::IsMember({"easy", "hard"}));
  auto* minutes =
      p->add_option("--minutes", args.minutes, "the round's time (default: the level's, 6 easy, 5 hard)")
          ->check(CLI::Range(0.1, 600.0));
  auto* speed = p->add_option("--speed", args.speed, "game seconds per second of the clock (bots only)")
                    ->default_val(1.0)
                    ->check(CLI::Range(0.1, 20.0));
  auto* as_json =
      p->add_flag("--json", args.json, "print one JSON object at the end: the summary and the verdicts");
  for (CLI::Option* o : {level, minutes, speed, as_json}) o->needs(bots);
  p->callback([&runner] {
    runner = [] {
      if (!args.bots && args.bot.empty()) return fail("give --bots, or --bot vive|phantom with --server URL");
      return args.bots ? museum_play_bots(args) : museum_play_one(args);
    };
  });
}

}  // namespace uh::cli
