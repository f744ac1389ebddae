#pragma once
// The sliding stretches of a trace (the strokes and the contour) as the friction and texture
// estimators read them.

#include <cstddef>
#include <vector>

#include "uh/core/math.hpp"
#include "uh/exploration/explore_trace.hpp"

namespace uh::exploration {

// The samples of one sliding stretch with, for each, the distance the tool's contact travelled,
// its motion direction (over about a millimetre of path) and the force split into the part against
// that motion and the part across it.
//
// The contact is where the tool is. Through the proxy a spring holds the tool to the hand, as stiff
// along the surface as across it (the stiffness the presses read), so the tool is the handle plus
// the force over that stiffness: the hand presses a millimetre (on a soft face ten) under the
// surface, slides on a line the tool does not follow on a curved face, and leads it by the
// friction's stretch of the spring. Friction opposes the tool's motion and a texture is where the
// tool touches, so both are read along its path. On the penalty path the tool is at the handle (its
// friction's stick spring ties it to the surface instead) and so is the contact (stiffness 0).
struct Slide {
  std::vector<double> time;
  std::vector<double> travel;  // along the contact's path [m]
  std::vector<double> normal_n;
  std::vector<double> friction_ratio;  // the force against the contact's motion over the force across it
  std::vector<double> pulled_n;        // the force against the hand's motion [N]
  std::vector<Vec3> position;  // the handle's [m]
  std::vector<Vec3> contact;   // where the tool is (above) [m]
  // the tool's centre on the surface it presses: the contact through the proxy; on the penalty path,
  // where the tool sinks in, the handle plus the force across the motion over the stiffness [m]
  std::vector<Vec3> centre;
  std::vector<Vec3> force;     // the force felt [N]
};

// the stretch of the samples `idx` of the trace (empty under 8 samples); `stiffness` [N/m] the
// spring that holds the tool to the hand (0: the contact is the handle), `sunk_stiffness` the
// contact's spring when the tool sinks in (0: it does not)
Slide slide_of(const ExploreTrace& trace, const std::vector<std::size_t>& idx, double stiffness,
               double sunk_stiffness);

// Whether one spring holds the tool to the hand (a proxy): the stick's ramp at the start of the
// strokes (the force along the surface per metre the hand pulls, the tool at rest) is within 1.4 times
// `stiffness` [N/m] either way; on the penalty path the ramp is the friction's stick spring.
bool hand_spring_holds_the_tool(const ExploreTrace& trace, double stiffness);

// each stroke's stretch (+e1, -e1, +e2, -e2) and the contour's
struct StrokeSlides {
  Slide legs[4];
  Slide contour;
};

// (its contact the handle plus the force over `stiffness` when hand_spring_holds_the_tool)
StrokeSlides stroke_slides(const ExploreTrace& trace, double stiffness);

}  // namespace uh::exploration
