#pragma once
/// \file
/// Logging for non-real-time threads: a thin layer over spdlog with fmt-style formatting.
///
///   uh::log::info("loaded {} ({} triangles)", path, count);
///
/// Thread rules: any thread that may block (setup, UI, reporting threads). Never from a real-time
/// path (haptic tick, collision query): formatting allocates and the sink locks. Real-time code
/// counts events with uh::EventCounter instead, and a non-real-time thread reports the counts.

#include <cstdint>
#include <string_view>
#include <utility>

#include <fmt/format.h>

namespace uh::log {

/// Severity, lowest first. Messages below the current level are dropped before formatting.
enum class Level : int { trace = 0, debug, info, warn, error, off };

/// Sets the lowest level written (default: info). Any thread.
void set_level(Level level);
/// The current level. Any thread.
[[nodiscard]] Level level();
/// True if a message at `level` would be written.
[[nodiscard]] bool enabled(Level level);

/// Writes an already formatted message. Not real-time safe.
void write(Level level, std::string_view message);

/// Messages written at `level` since the process started (dropped ones excluded), e.g. for tests
/// that must fail when a warning fired. Any thread.
[[nodiscard]] std::uint64_t message_count(Level level);

template <typename... Ts>
void trace(fmt::format_string<Ts...> format, Ts&&... args) {
  if (enabled(Level::trace)) write(Level::trace, fmt::format(format, std::forward<Ts>(args)...));
}
template <typename... Ts>
void debug(fmt::format_string<Ts...> format, Ts&&... args) {
  if (enabled(Level::debug)) write(Level::debug, fmt::format(format, std::forward<Ts>(args)...));
}
template <typename... Ts>
void info(fmt::format_string<Ts...> format, Ts&&... args) {
  if (enabled(Level::info)) write(Level::info, fmt::format(format, std::forward<Ts>(args)...));
}
template <typename... Ts>
void warn(fmt::format_string<Ts...> format, Ts&&... args) {
  if (enabled(Level::warn)) write(Level::warn, fmt::format(format, std::forward<Ts>(args)...));
}
template <typename... Ts>
void error(fmt::format_string<Ts...> format, Ts&&... args) {
  if (enabled(Level::error)) write(Level::error, fmt::format(format, std::forward<Ts>(args)...));
}

}  // namespace uh::log
