// uh serve [--host 127.0.0.1] [--port 7770] [--token T] [--root DIR] [--allow-any-path] [--no-realtime]
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <string>

#include <fmt/format.h>

#include "commands.hpp"
#include "uh/service/server.hpp"
#include "view_assets.hpp"

namespace uh::cli {
namespace {

struct ServeArgs {
  std::string host = "127.0.0.1";
  int port = 7770;
  std::string token;
  std::string root;
  bool allow_any_path = false;
  bool no_realtime = false;
};

int serve(const ServeArgs& args) {
  const sigset_t stop_signals = block_stop_signals();

  auto server = service::Server::start(
      {.host = args.host,
       .port = static_cast<std::uint16_t>(args.port),
       .token = args.token,
       .files = view::static_files(),
       .working_dir = args.root.empty() ? std::filesystem::path{} : std::filesystem::absolute(args.root),
       .allow_any_path = args.allow_any_path,
       .raise_priority = !args.no_realtime});
  if (!server) {
    const std::string& m = server.error().message;
    return fail(m.find("token is required") != std::string::npos ? m + " (give --token)" : m);
  }
  const std::string url = (*server)->url();
  const std::string ws = "ws" + url.substr(4) + "ws";
  std::printf("uh serve: listening on %s (live view: %s); Ctrl-C stops\n", ws.c_str(), url.c_str());
  std::fflush(stdout);
  wait_for_stop_signal(stop_signals);
  (*server)->stop();
  std::printf("uh serve: stopped\n");
  return 0;
}

}  // namespace

sigset_t block_stop_signals() {
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  // a closed terminal or SSH session (SIGHUP) and SIGQUIT stop as Ctrl-C does; a client gone
  // away is a write error on its socket, never a SIGPIPE that ends the program
  for (const int s : {SIGINT, SIGTERM, SIGHUP, SIGQUIT}) sigaddset(&stop_signals, s);
  std::signal(SIGPIPE, SIG_IGN);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);
  return stop_signals;
}

int wait_for_stop_signal(const sigset_t& stop_signals) {
  int signal = 0;
  sigwait(&stop_signals, &signal);
  return signal;
}

void add_serve_command(CLI::App& app, CommandRunner& runner) {
  static ServeArgs args;
  auto* s = app.add_subcommand("serve",
                               "run haptic sessions as a WebSocket service, with a live view in the browser");
  s->add_option("--host", args.host, "address to listen on (other than loopback: a token is required)")
      ->default_val("127.0.0.1");
  s->add_option("--port", args.port, "port (0: any free port, printed)")
      ->default_val(7770)
      ->check(CLI::Range(0, 65535));
  s->add_option("--token", args.token, "clients must send this token in their hello");
  s->add_option(
       "--root", args.root,
       "the folder clients name files in (relative paths start there); they may name files in it and "
       "in the cache only (default: the working folder)")
      ->check(CLI::ExistingDirectory);
  s->add_flag("--allow-any-path", args.allow_any_path,
              "let clients name any file this user can read, outside --root and the cache");
  s->add_flag("--no-realtime", args.no_realtime,
              "do not ask for SCHED_FIFO for the sessions' haptic and collision threads");
  s->callback([&runner] { runner = [] { return serve(args); }; });
}

}  // namespace uh::cli
