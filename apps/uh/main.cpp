// uh: the command-line program of UnrealHaptics.
#include <CLI/CLI.hpp>

#include <cstdio>

#include "commands.hpp"

namespace uh::cli {

int fail(const std::string& message) {
  std::fprintf(stderr, "uh: %s\n", message.c_str());
  return 1;
}

}  // namespace uh::cli

int main(int argc, char** argv) {
  CLI::App app{"uh: build Inner Sphere Trees, query them, list haptic devices and run haptic sessions"};
  app.set_version_flag("--version", "uh " UH_VERSION_STRING);
  app.require_subcommand(1);
  uh::cli::CommandRunner runner;
  uh::cli::add_devices_command(app, runner);
  uh::cli::add_explore_command(app, runner);
  uh::cli::add_ist_commands(app, runner);
  uh::cli::add_mesh_command(app, runner);
  uh::cli::add_query_command(app, runner);
  uh::cli::add_run_command(app, runner);
  uh::cli::add_serve_command(app, runner);
  uh::cli::add_museum_commands(app, runner);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  return runner ? runner() : 2;
}
