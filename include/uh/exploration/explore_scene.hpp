#pragma once
/// \file
/// Exploring the objects of a scene: each alone with the scene's tool, on a simulated hand that
/// follows the script, in simulated time; the material estimated from each trace.

#include <cstdint>
#include <string>
#include <vector>

#include "uh/controllers/haptic_session.hpp"
#include "uh/controllers/scene.hpp"
#include "uh/core/result.hpp"
#include "uh/exploration/material_estimate.hpp"

namespace uh::exploration {

/// One object explored.
struct ObjectExploration {
  std::string object;
  MaterialEstimate estimate;
  ExploreTrace trace;
  /// Through the proxy, the stiffest spring the device renders [N/m]: the coupling's stiffness
  /// clamped to Colgate's passivity bound for the device's damping at the haptic period. A material
  /// stiffer than it reads as it (the rendered stiffness, not the material's). 0 on the penalty path.
  double rendered_stiffness_limit_n_per_m = 0.0;
  double work_on_hand_j = 0.0;  ///< energy the device put into the hand over the whole (closed) script [J]
  double simulated_s = 0.0;     ///< simulated time the script took [s]
  std::uint64_t haptic_ticks = 0;
};

/// Explores object `object_name` of `scene` (every object when empty), each alone with the
/// scene's tool, on a simulated hand that follows the script; stepped, in simulated time.
Result<std::vector<ObjectExploration>> explore_scene(const controllers::Scene& scene, const std::string& object_name,
                                                     const ExploreOptions& options,
                                                     const controllers::SessionOptions& session = {});

}  // namespace uh::exploration
