#pragma once
// The sliding stretches of a trace (the strokes and the contour) as the friction and texture
// estimators read them.

#include <cstddef>
#include <vector>

#include "uh/core/math.hpp"
#include "uh/exploration/explore_trace.hpp"

namespace uh::exploration {

// The samples of one sliding stretch with, for each, the distance travelled, the motion
// direction (over about a millimetre of path) and the force split into normal and tangential parts
struct Slide {
  std::vector<double> time;
  std::vector<double> travel;
  std::vector<double> normal_n;
  std::vector<double> friction_ratio;
  std::vector<Vec3> position;
  std::vector<Vec3> force;  // the force felt [N]
};

// the stretch of the samples `idx` of the trace (empty under 8 samples)
Slide slide_of(const ExploreTrace& trace, const std::vector<std::size_t>& idx);

// each stroke's stretch (+e1, -e1, +e2, -e2) and the contour's
struct StrokeSlides {
  Slide legs[4];
  Slide contour;
};

StrokeSlides stroke_slides(const ExploreTrace& trace);

}  // namespace uh::exploration
