#pragma once
/// \file
/// A PNG of a haptic session: force and torque magnitude and the collision rate over time
/// (cairo). What `uh run --plot` writes.

#include <filesystem>

#include <string>
#include <vector>

#include "uh/controllers/haptic_session.hpp"
#include "uh/core/result.hpp"
#include "uh/exploration/exploration.hpp"

namespace uh::cli {

/// Writes the plot atomically (temporary file, then rename). Errors name the file.
Status write_session_plot(const controllers::SessionReport& report, const std::filesystem::path& png);

/// The forces felt while stroking each explored object (`uh explore --plot`): one panel per
/// object, the normal force and the friction (against the motion) over the strokes and the contour.
Status write_exploration_plot(const std::string& scene,
                              const std::vector<exploration::ObjectExploration>& objects,
                              const std::filesystem::path& png);

}  // namespace uh::cli
