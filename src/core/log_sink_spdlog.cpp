#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "log_sink.hpp"

namespace uh::log::detail {
namespace {

spdlog::level::level_enum to_spdlog(Level level) {
  switch (level) {
    case Level::trace:
      return spdlog::level::trace;
    case Level::debug:
      return spdlog::level::debug;
    case Level::info:
      return spdlog::level::info;
    case Level::warn:
      return spdlog::level::warn;
    case Level::error:
      return spdlog::level::err;
    case Level::off:
      return spdlog::level::off;
  }
  return spdlog::level::off;
}

// Messages go to stderr, as the stderr sink's do: spdlog's default logger writes to stdout, where
// they would mix into what the commands print (`--json` documents, a served port).
spdlog::logger& logger() {
  static const std::shared_ptr<spdlog::logger> to_stderr = spdlog::stderr_color_mt("uh");
  return *to_stderr;
}

}  // namespace

// the logger filters too: let everything through that passes our level
void sink_set_level(Level level) { logger().set_level(to_spdlog(level)); }

void sink_write(Level level, std::string_view message) { logger().log(to_spdlog(level), "{}", message); }

}  // namespace uh::log::detail
