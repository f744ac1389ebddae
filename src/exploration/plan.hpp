#pragma once
// The planner: where the hand starts, which way it goes in, the stroke axes, and where each press
// and each pair of strokes begins; from the packed shapes' geometry before the run, never their material.

#include <cstdint>

#include "uh/collette/sphere_tree.hpp"
#include "uh/core/math.hpp"
#include "uh/core/result.hpp"
#include "uh/exploration/explore_options.hpp"

namespace uh::exploration {

struct ExplorePlan {
  Vec3 start{};
  Vec3 approach{0, 0, -1};
  Vec3 axes[2]{};
  Vec3 axis_point{};  // on the footprint's vertical centre line
};

// The start 3 mm off the object where the site says (the seed moves it by up to 3 mm across the
// approach), the approach direction and the stroke axes; `surface_gap_m` more where the tool will
// rest on a mesh surface up to that far above the object's spheres
Result<ExplorePlan> plan_exploration(const collette::SphereTree& object, const Pose& world_from_object,
                                     const collette::SphereTree& tool, const ExploreOptions& options,
                                     double surface_gap_m);

// the length of stroke `leg` (0, 1 along e1; 2, 3 along e2) [m]
double leg_length(const ExploreOptions& o, std::int32_t leg);

// where press `press` (1..) goes: press_spread_m from the site on the diagonals between the stroke axes
Vec3 press_spot(const ExplorePlan& plan, const ExploreOptions& o, int press);

// half a stroke before the site along the pair's axis (strokes_through_site)
Vec3 stroke_start(const ExplorePlan& plan, const ExploreOptions& o, std::int32_t leg);

}  // namespace uh::exploration
