#pragma once
/// \file
/// The subcommands of `uh`. Each registers its options on a CLI11 app and returns the exit code
/// of its run: 0 success, 1 a user-facing error (already printed to stderr), 2 bad usage.

#include <CLI/CLI.hpp>
#include <nlohmann/json_fwd.hpp>

#include <csignal>
#include <functional>

namespace uh::museum_players {
struct FeatureDifference;
}

namespace uh::cli {

/// Runs after parsing; returns the process exit code.
using CommandRunner = std::function<int()>;

void add_devices_command(CLI::App& app, CommandRunner& runner);
void add_explore_command(CLI::App& app, CommandRunner& runner);
void add_ist_commands(CLI::App& app, CommandRunner& runner);
void add_mesh_command(CLI::App& app, CommandRunner& runner);
void add_query_command(CLI::App& app, CommandRunner& runner);
void add_run_command(CLI::App& app, CommandRunner& runner);
void add_serve_command(CLI::App& app, CommandRunner& runner);
void add_museum_commands(CLI::App& app, CommandRunner& runner);
/// `uh museum station` (Phantom's station), on `museum`, when the build has sound.
void add_museum_station_command(CLI::App& museum, CommandRunner& runner);
/// One piece of the blind player's evidence as `uh museum judge --json` and `uh museum play` print it.
nlohmann::json evidence_json(const museum_players::FeatureDifference& f);

/// Blocks SIGINT, SIGTERM, SIGHUP and SIGQUIT (and ignores SIGPIPE) in the calling thread, before a server's
/// threads start (they inherit the mask, so no thread is interrupted by them); wait_for_stop_signal() then
/// takes them.
sigset_t block_stop_signals();
/// Waits for SIGINT, SIGTERM, SIGHUP or SIGQUIT (blocked by block_stop_signals()); returns which came.
int wait_for_stop_signal(const sigset_t& stop_signals);

/// Prints "uh: <message>" to stderr and returns 1.
int fail(const std::string& message);

}  // namespace uh::cli
