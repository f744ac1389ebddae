#include "uh/exploration/material_estimate.hpp"

#include "estimators.hpp"

namespace uh::exploration {
namespace {

// by default a press stops at this share of the force limit: the samples it fits are never clamped
constexpr double kPressShareOfLimit = 0.9;

}  // namespace

double press_stop_force_n(const ExploreOptions& options, double force_limit_n) {
  return options.press_force_n.value_or(kPressShareOfLimit * force_limit_n);
}

MaterialEstimate estimate_material(const ExploreTrace& trace) {
  MaterialEstimate e;
  estimate_stiffness(trace, e);
  estimate_damping(trace, e);
  const StrokeSlides slides = stroke_slides(trace, e.stiffness_n_per_mm.value_or(0.0) * 1e3);
  estimate_friction(slides, trace.options, e);
  estimate_texture(slides, trace, e);  // after the stiffness, which it reads
  return e;
}

}  // namespace uh::exploration
