#include <chrono>
#include <cstdio>
#include <mutex>
#include <string>

#include <fmt/chrono.h>
#include <fmt/format.h>

#include "log_sink.hpp"

namespace uh::log::detail {
namespace {

std::string_view level_name(Level level) {
  switch (level) {
    case Level::trace:
      return "trace";
    case Level::debug:
      return "debug";
    case Level::info:
      return "info";
    case Level::warn:
      return "warning";
    case Level::error:
      return "error";
    case Level::off:
      break;
  }
  return "off";
}

}  // namespace

void sink_set_level(Level) {}

// spdlog's default layout, "[2026-01-01 12:00:00.123] [info] message", as one write per line so
// that lines from several threads never interleave
void sink_write(Level level, std::string_view message) {
  const auto now = std::chrono::system_clock::now();
  const auto ms =
      std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  const std::string line =
      fmt::format("[{:%Y-%m-%d %H:%M:%S}.{:03d}] [{}] {}\n", std::chrono::floor<std::chrono::seconds>(now),
                  ms, level_name(level), message);
  static std::mutex mutex;
  const std::lock_guard lock(mutex);
  std::fwrite(line.data(), 1, line.size(), stderr);
  std::fflush(stderr);
}

}  // namespace uh::log::detail
