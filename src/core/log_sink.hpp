#pragma once
// Where uh::log's messages go: spdlog where the build has it (log_sink_spdlog.cpp), else stderr
// (log_sink_stderr.cpp, the Windows build). log.cpp filters and counts; the sink only writes.

#include <string_view>

#include "uh/core/log.hpp"

namespace uh::log::detail {

/// Told every level change (spdlog filters on its own as well).
void sink_set_level(Level level);
/// Writes one message that passed the level filter. Any thread; may lock; not real-time safe.
void sink_write(Level level, std::string_view message);

}  // namespace uh::log::detail
