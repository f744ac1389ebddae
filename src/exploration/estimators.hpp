#pragma once
// The estimators, one per property the trace tells, each reading the trace alone (never the
// scene's material values); estimate_material (material_estimate.cpp) runs them in turn.

#include "slide.hpp"
#include "uh/exploration/material_estimate.hpp"

namespace uh::exploration {

// stiffness_n_per_mm, stiffness_per_press_n_per_mm, press_reach_m: from the presses
void estimate_stiffness(const ExploreTrace& trace, MaterialEstimate& e);

// damping_n_s_per_m, damping_per_press_n_s_per_m: from the loops between the presses and their releases
void estimate_damping(const ExploreTrace& trace, MaterialEstimate& e);

// friction_static, friction_dynamic: from the strokes and the contour
void estimate_friction(const StrokeSlides& slides, const ExploreOptions& o, MaterialEstimate& e);

// texture_ripple_n, ripple_axis_n, period_axis_m, sine_share_axis, texture_wave_share, texture_period_m: from
// the strokes' and the contour's normal force ripple (reads e.stiffness_n_per_mm)
void estimate_texture(const StrokeSlides& slides, const ExploreTrace& trace, MaterialEstimate& e);

}  // namespace uh::exploration
