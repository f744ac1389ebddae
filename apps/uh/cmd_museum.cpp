// uh museum serve [--host 127.0.0.1] [--port 7780] [--token T] [--seed N] [--minutes M] [--level easy|hard]
//                  [--speed S]
// uh museum judge [--level easy|hard] [--seed N] [--kinds K,...] [--json]
// uh museum play: cmd_museum_play.cpp
#include <cstdio>
#include <optional>
#include <random>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "museum_client.hpp"
#include "progress_bar.hpp"
#include "uh/museum/level.hpp"
#include "uh/museum_players/blind_player.hpp"
#include "uh/museum_artifacts/artifact.hpp"
#include "uh/museum_service/game_server.hpp"

namespace uh::cli {
namespace {

struct MuseumServeArgs {
  std::string host = "127.0.0.1";
  int port = 7780;
  std::string token;
  std::optional<std::uint64_t> seed;  // none: a fresh one each round (players must not know it)
  double minutes = 0.0;  // 0: the level's own round time
  std::string level = "easy";
  double speed = 1.0;  // game seconds per second of the clock
};

int museum_serve(const MuseumServeArgs& args) {
  const sigset_t stop_signals = block_stop_signals();
  museum::Level level =
      museum::make_level(args.level == "hard" ? museum::Difficulty::hard : museum::Difficulty::easy);
  if (args.minutes > 0.0) level.rules.round_s = args.minutes * 60.0;
  level.pieces = museum_artifacts::piece_pairs(level);  // what Phantom's station is told to build
  // the seed deals where the forgeries are: a fixed default would let a player deal the same round
  // offline and read the answers, so an unseeded round draws one from the system
  const std::uint64_t seed =
      args.seed ? *args.seed : (std::uint64_t{std::random_device{}()} << 32) ^ std::random_device{}();
  const MuseumClientFiles client = museum_client_files(level);  // Vive's page, served at `/`
  auto server = museum_service::GameServer::start({.host = args.host,
                                                   .port = static_cast<std::uint16_t>(args.port),
                                                   .token = args.token,
                                                   .level = std::move(level),
                                                   .seed = seed,
                                                   .speed = args.speed,
                                                   .files = client.files});
  if (!server) {
    const std::string& m = server.error().message;
    return fail(m.find("token is required") != std::string::npos ? m + " (give --token)" : m);
  }
  const std::string url = (*server)->url();
  std::printf("uh museum serve: %s level, seed %llu%s%s; players connect to ws%sws; Ctrl-C stops\n",
              args.level.c_str(), static_cast<unsigned long long>(seed),
              args.seed ? "" : " (drawn; --seed replays the round)",
              args.speed != 1.0 ? fmt::format(", at {:g} times the clock", args.speed).c_str() : "",
              url.substr(4).c_str());
  if (client.has_page) std::printf("uh museum serve: Vive plays in a browser at %s\n", url.c_str());
  std::fflush(stdout);
  wait_for_stop_signal(stop_signals);
  (*server)->stop();
  std::printf("uh museum serve: stopped\n");
  return 0;
}

struct MuseumJudgeArgs {
  std::string level = "easy";
  std::uint64_t seed = 1;
  std::vector<std::string> kinds;
  bool json = false;
};

museum::Difficulty difficulty_named(const std::string& level) {
  return level == "hard" ? museum::Difficulty::hard : museum::Difficulty::easy;
}


int museum_judge(const MuseumJudgeArgs& args) {
  museum_players::JudgeOptions options;
  options.difficulty = difficulty_named(args.level);
  options.seed = args.seed;
  if (!args.kinds.empty()) {
    options.kinds.clear();
    for (const std::string& name : args.kinds) {
      const auto kind = museum_artifacts::artifact_kind(name);
      if (!kind)
        return fail(fmt::format(
            "--kinds: '{}' is no artifact kind (amphora, bowl, coin, tablet, scarab, goblet)", name));
      options.kinds.push_back(*kind);
    }
  }
  ProgressBar bar("judging");  // one bar over all of the judge's stages
  options.progress = [&bar](const std::string&, double fraction) { bar.update(fraction); };
  auto report = museum_players::run_judge(options);
  bar.finish();
  if (!report) return fail(report.error().message);
  if (args.json) {
    nlohmann::json pairs = nlohmann::json::array();
    for (const auto& pair : report->pairs) {
      nlohmann::json pieces = nlohmann::json::array();
      for (const auto& p : pair.pieces) {
        nlohmann::json evidence = nlohmann::json::array();
        for (const auto& f : p.judgement.evidence) evidence.push_back(evidence_json(f));
        pieces.push_back({{"truth", museum_artifacts::to_string(p.truth)},
                          {"verdict", museum_players::to_string(p.judgement.verdict)},
                          {"correct", p.correct()},
                          {"turn_deg", p.turn_rad * 180.0 / kPi},
                          {"simulated_s", p.simulated_s},
                          {"evidence", evidence}});
      }
      pairs.push_back({{"kind", museum_artifacts::to_string(pair.kind)},
                       {"tell", pair.tell},
                       {"material_tell", pair.material_tell},
                       {"pieces", pieces}});
    }
    const nlohmann::json out{{"level", args.level},
                             {"seed", args.seed},
                             {"accuracy", report->accuracy},
                             {"simulated_s", report->simulated_s},
                             {"pairs", pairs}};
    std::printf("%s\n", out.dump(2).c_str());
    return 0;
  }
  std::printf("uh museum judge: %s level, seed %llu\n", args.level.c_str(),
              static_cast<unsigned long long>(args.seed));
  for (const auto& pair : report->pairs) {
    for (const auto& p : pair.pieces) {
      std::string evidence;
      for (const auto& f : p.judgement.evidence) {
        if (!evidence.empty()) evidence += "; ";
        evidence += fmt::format("{}{} {:.2f}{} (threshold {:.2f}{}{}){}", f.feature,
                                f.where.empty() ? "" : " (" + f.where + ")", f.difference, f.unit,
                                f.threshold, f.unit, f.p_value ? fmt::format(", p {:.2g}", *f.p_value) : "",
                                f.differs() ? " DIFFERS" : "");
      }
      std::printf("  %-8s %-8s -> %-8s %s  %s\n", museum_artifacts::to_string(pair.kind),
                  museum_artifacts::to_string(p.truth), museum_players::to_string(p.judgement.verdict),
                  p.correct() ? "right" : "WRONG", evidence.c_str());
    }
  }
  std::printf("accuracy %.3f (%.0f s of simulated exploration)\n", report->accuracy, report->simulated_s);
  return 0;
}

}  // namespace

nlohmann::json evidence_json(const museum_players::FeatureDifference& f) {
  nlohmann::json j = {{"feature", f.feature},  {"where", f.where},         {"difference", f.difference},
                      {"noise", f.noise},      {"threshold", f.threshold}, {"unit", f.unit},
                      {"differs", f.differs()}};
  if (f.p_value) j["p_value"] = *f.p_value;
  return j;
}

void add_museum_play_command(CLI::App& museum, CommandRunner& runner);  // cmd_museum_play.cpp

void add_museum_commands(CLI::App& app, CommandRunner& runner) {
  auto* museum = app.add_subcommand("museum", "the museum heist game (docs/museum.md)");
  museum->require_subcommand(1);
  static MuseumServeArgs args;
  auto* s = museum->add_subcommand("serve", "run a round's authoritative server over WebSocket");
  s->add_option("--host", args.host, "address to listen on (other than loopback: a token is required)")
      ->default_val("127.0.0.1");
  s->add_option("--port", args.port, "port (0: any free port, printed)")
      ->default_val(7780)
      ->check(CLI::Range(0, 65535));
  s->add_option("--token", args.token, "clients must send this token in their hello");
  s->add_option("--seed", args.seed,
                "deals the round: targets, where the forgeries are, the guards' starts (default: drawn)");
  s->add_option("--minutes", args.minutes, "the round's time (default: the level's, 6 easy, 5 hard)")
      ->check(CLI::Range(0.1, 600.0));
  s->add_option("--level", args.level, "easy or hard")
      ->default_val("easy")
      ->check(CLI::IsMember({"easy", "hard"}));
  s->add_option("--speed", args.speed, "game seconds per second of the clock (tests, demonstrations)")
      ->default_val(1.0)
      ->check(CLI::Range(0.1, 20.0));
  s->callback([&runner] { runner = [] { return museum_serve(args); }; });

  static MuseumJudgeArgs judge;
  auto* j = museum->add_subcommand(
      "judge", "run the automated blind player over every artifact pair of a level and print its accuracy");
  j->add_option("--level", judge.level, "easy or hard")
      ->default_val("easy")
      ->check(CLI::IsMember({"easy", "hard"}));
  j->add_option("--seed", judge.seed,
                "deals the order and the turns of the pieces and the exploration's spots")
      ->default_val(1);
  j->add_option("--kinds", judge.kinds, "only these artifact kinds (default: all six)")->delimiter(',');
  j->add_flag("--json", judge.json,
              "print one JSON object: accuracy and per pair the verdicts and the evidence");
  j->callback([&runner] { runner = [] { return museum_judge(judge); }; });

  add_museum_play_command(*museum, runner);
#ifdef UH_HAS_MUSEUM_STATION
  add_museum_station_command(*museum, runner);
#endif
}

}  // namespace uh::cli
