// Friction: per stroke, the largest ratio of the force against the motion to the force across it
// before a third of the stroke (breakaway) and the median ratio over its second half (sliding);
// the contour's median ratio joins the sliding ones. The static and dynamic coefficients are the
// means over the strokes.

#include <algorithm>
#include <limits>
#include <numeric>
#include <optional>
#include <vector>

#include "estimators.hpp"
#include "plan.hpp"
#include "uh/core/statistics.hpp"

namespace uh::exploration {
namespace {

// The breakaway of one stroke: the largest force against the motion over the first third, over
// the median force across it there (a texture ripples the force across the motion, not the
// friction the stick point holds: a tick's own ratio would read the ripple's troughs); -1e300 when
// the first third has no sample
double breakaway_ratio(const Slide& s, double length) {
  double peak = -1e300;
  std::vector<double> across;
  for (std::size_t j = 0; j < s.travel.size(); ++j)
    if (s.travel[j] < length / 3.0) {
      peak = std::max(peak, s.friction_ratio[j] * s.normal_n[j]);
      across.push_back(s.normal_n[j]);
    }
  if (!across.empty()) peak /= core::median(across);
  return peak;
}

// the median ratio over the samples of `s` travelled between `from_m` and `to_m` (exclusive)
std::optional<double> sliding_ratio(const Slide& s, double from_m, double to_m) {
  std::vector<double> slid;
  for (std::size_t j = 0; j < s.travel.size(); ++j)
    if (s.travel[j] > from_m && s.travel[j] < to_m) slid.push_back(s.friction_ratio[j]);
  if (slid.empty()) return std::nullopt;
  return core::median(slid);
}

double mean(const std::vector<double>& v) {
  return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
}

}  // namespace

void estimate_friction(const StrokeSlides& slides, const ExploreOptions& o, MaterialEstimate& e) {
  std::vector<double> breakaway, sliding;
  for (int leg = 0; leg < 4; ++leg) {
    const Slide& s = slides.legs[leg];
    if (s.travel.empty()) continue;
    const double length = leg_length(o, leg);
    if (const double peak = breakaway_ratio(s, length); peak > -1e300) breakaway.push_back(peak);
    if (const auto slid = sliding_ratio(s, 0.5 * length, 0.95 * length)) sliding.push_back(*slid);
  }
  // the contour past its first quarter
  const double circle = 2.0 * kPi * o.contour_radius_m;
  if (const auto slid = sliding_ratio(slides.contour, 0.25 * circle, std::numeric_limits<double>::infinity())) sliding.push_back(*slid);
  if (!breakaway.empty()) e.friction_static = std::max(0.0, mean(breakaway));
  if (!sliding.empty()) e.friction_dynamic = std::max(0.0, mean(sliding));
}

}  // namespace uh::exploration
