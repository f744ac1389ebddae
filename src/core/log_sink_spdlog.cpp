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

}  // namespace

// the default spdlog logger filters too: let everything through that passes our level
void sink_set_level(Level level) { spdlog::set_level(to_spdlog(level)); }

void sink_write(Level level, std::string_view message) { spdlog::log(to_spdlog(level), "{}", message); }

}  // namespace uh::log::detail
