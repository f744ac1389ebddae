// uh museum serve [--host 127.0.0.1] [--port 7780] [--token T] [--seed N] [--minutes M] [--level easy|hard]
#include <cstdio>
#include <string>

#include <fmt/format.h>

#include "commands.hpp"
#include "museum_client.hpp"
#include "uh/museum/level.hpp"
#include "uh/museum_service/game_server.hpp"

namespace uh::cli {
namespace {

struct MuseumServeArgs {
  std::string host = "127.0.0.1";
  int port = 7780;
  std::string token;
  std::uint64_t seed = 1;
  double minutes = 0.0;  // 0: the level's own round time
  std::string level = "easy";
};

int museum_serve(const MuseumServeArgs& args) {
  const sigset_t stop_signals = block_stop_signals();
  museum::Level level =
      museum::make_level(args.level == "hard" ? museum::Difficulty::hard : museum::Difficulty::easy);
  if (args.minutes > 0.0) level.rules.round_s = args.minutes * 60.0;
  const MuseumClientFiles client = museum_client_files(level);  // Vive's page, served at `/`
  auto server = museum_service::GameServer::start({.host = args.host,
                                                   .port = static_cast<std::uint16_t>(args.port),
                                                   .token = args.token,
                                                   .level = std::move(level),
                                                   .seed = args.seed,
                                                   .files = client.files});
  if (!server) {
    const std::string& m = server.error().message;
    return fail(m.find("token is required") != std::string::npos ? m + " (give --token)" : m);
  }
  const std::string url = (*server)->url();
  std::printf("uh museum serve: %s level, seed %llu; players connect to ws%sws; Ctrl-C stops\n",
              args.level.c_str(), static_cast<unsigned long long>(args.seed), url.substr(4).c_str());
  if (client.has_page) std::printf("uh museum serve: Vive plays in a browser at %s\n", url.c_str());
  std::fflush(stdout);
  wait_for_stop_signal(stop_signals);
  (*server)->stop();
  std::printf("uh museum serve: stopped\n");
  return 0;
}

}  // namespace

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
  s->add_option("--seed", args.seed, "deals the round: targets, where the forgeries are, the guards' starts")
      ->default_val(1);
  s->add_option("--minutes", args.minutes, "the round's time (default: the level's, 6 easy, 5 hard)")
      ->check(CLI::Range(0.1, 600.0));
  s->add_option("--level", args.level, "easy or hard")
      ->default_val("easy")
      ->check(CLI::IsMember({"easy", "hard"}));
  s->callback([&runner] { runner = [] { return museum_serve(args); }; });
}

}  // namespace uh::cli
