#include "uh/core/log.hpp"

#include <array>
#include <atomic>

#include "log_sink.hpp"

namespace uh::log {
namespace {

std::atomic<int> g_level{static_cast<int>(Level::info)};
std::array<std::atomic<std::uint64_t>, 6> g_counts{};

}  // namespace

void set_level(Level level) {
  g_level.store(static_cast<int>(level), std::memory_order_relaxed);
  detail::sink_set_level(level);
}

Level level() { return static_cast<Level>(g_level.load(std::memory_order_relaxed)); }

bool enabled(Level l) { return l != Level::off && static_cast<int>(l) >= g_level.load(std::memory_order_relaxed); }

void write(Level l, std::string_view message) {
  if (!enabled(l)) return;
  g_counts[static_cast<std::size_t>(l)].fetch_add(1, std::memory_order_relaxed);
  detail::sink_write(l, message);
}

std::uint64_t message_count(Level l) { return g_counts[static_cast<std::size_t>(l)].load(std::memory_order_relaxed); }

}  // namespace uh::log
