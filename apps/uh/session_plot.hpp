#pragma once
/// \file
/// A PNG of a haptic session: force and torque magnitude and the collision rate over time
/// (cairo). What `uh run --plot` writes.

#include <filesystem>

#include "uh/controllers/haptic_session.hpp"
#include "uh/core/result.hpp"

namespace uh::cli {

/// Writes the plot atomically (temporary file, then rename). Errors name the file.
Status write_session_plot(const controllers::SessionReport& report, const std::filesystem::path& png);

}  // namespace uh::cli
