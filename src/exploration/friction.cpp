// Friction: per stroke, the largest ratio of the force against the motion to the force across it
// before a third of the stroke (breakaway) and the median ratio over its second half (sliding);
// the contour's median ratio joins the sliding ones. The static and dynamic coefficients are the
// means over the strokes.

#include <algorithm>
#include <limits>
#include <numeric>
#include <optional>
#include <vector>

#include <Eigen/Dense>

#include "estimators.hpp"
#include "plan.hpp"
#include "uh/core/statistics.hpp"

namespace uh::exploration {
namespace {

constexpr std::size_t kRampTicks = 5;  // the stick's ramp before the breakaway, read over this many ticks

// The stroke's surface as the tool's centre travelled it (Slide::centre): a reference normal, the
// stroke's direction across it, and the centre's height along that normal fitted by a parabola in
// its position along the stroke's direction (not in the distance travelled: the slope of height over
// position is the surface's tilt from the reference whatever that tilt, where the slope over
// distance, its sine, left a degree and a half of the force's mean tilt by the friction in the
// normal, and the breakaway read 0.56 for 0.6 on a flat face).
struct StrokeSurface {
  Vec3 mean_normal{};
  Vec3 along{};
  Eigen::Vector3d height{Eigen::Vector3d::Zero()};  // h = c0 + c1 u + c2 u^2, u = (x - mid) / half
  double mid = 0.0, half = 1.0;

  // the surface's normal under the tool's centre
  Vec3 normal_at(const Vec3& centre) const {
    const double u = (dot(centre, along) - mid) / half;
    const double slope = (height[1] + 2.0 * height[2] * u) / half;
    return normalized(mean_normal - slope * along);
  }
};

// Fits the tool centre's height along `surface.mean_normal` against its position along the stroke.
bool fit_height(const Slide& s, StrokeSurface& surface) {
  const Vec3 moved = s.centre.back() - s.centre.front();
  surface.along = normalized(moved - dot(moved, surface.mean_normal) * surface.mean_normal);
  if (norm(surface.along) == 0.0) return false;
  const double first = dot(s.centre.front(), surface.along), last = dot(s.centre.back(), surface.along);
  surface.mid = 0.5 * (first + last);
  surface.half = std::max(0.5 * std::abs(last - first), 1e-9);
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  Eigen::Vector3d atb = Eigen::Vector3d::Zero();
  for (const Vec3& c : s.centre) {
    const double u = (dot(c, surface.along) - surface.mid) / surface.half;
    const Eigen::Vector3d row(1.0, u, u * u);
    ata += row * row.transpose();
    atb += dot(c, surface.mean_normal) * row;
  }
  surface.height = ata.ldlt().solve(atb);
  return surface.height.allFinite();
}

// Fitted twice: first along the force's mean direction, which friction tilts (22 degrees at mu
// 0.4), so that a dome's arc lies off-centre in that frame and its end slopes, where the strokes
// break away, come out degrees off a parabola's; then along the normal the first fit found at the
// stroke's middle, where the arc is symmetric (within a degree of the dome's normal).
std::optional<StrokeSurface> stroke_surface(const Slide& s) {
  if (s.centre.size() < 16) return std::nullopt;
  StrokeSurface surface;
  for (const Vec3& f : s.force) surface.mean_normal += f;
  surface.mean_normal = normalized(surface.mean_normal);
  if (!fit_height(s, surface)) return std::nullopt;
  surface.mean_normal = normalized(surface.mean_normal - (surface.height[1] / surface.half) * surface.along);
  if (!fit_height(s, surface)) return std::nullopt;
  return surface;
}

// The breakaway of one stroke: at the tick of the largest force against the motion over the first
// third, the force along the surface over the force across it, in the surface's own frame there.
// Not in the frame of the hand's motion: while the tool sticks the hand moves on along the
// stroke's line, which on a curved surface is not its tangent, and each stroke breaks away uphill
// on a dome's flank (0.67 for 0.5 on the 4 cm dome through the proxy, read in the motion's frame).
// -1e300 when the first third has no sample.
double breakaway_ratio(const Slide& s, double length, const std::optional<StrokeSurface>& surface) {
  double peak = -1e300;
  std::size_t at = 0;
  for (std::size_t j = 0; j < s.travel.size(); ++j) {
    const double against = s.pulled_n[j];
    if (s.travel[j] < length / 3.0 && against > peak) {
      peak = against;
      at = j;
    }
  }
  if (peak <= -1e300 || !surface) return peak <= -1e300 ? peak : s.friction_ratio[at];
  const Vec3 n = surface->normal_at(s.centre[at]);
  const auto ratio = [&](std::size_t j) {
    const double pressing = dot(s.force[j], n);
    return pressing > 0.0 ? norm(s.force[j] - pressing * n) / pressing : s.friction_ratio[j];
  };
  // The tick of the peak is the last the tool stuck on: the cone's edge lies between its ratio and
  // the next tick's, had the tool stuck on, so half the ramp's rise per tick is added (up to 5 % of
  // mu_s low otherwise: 1.25 N/mm x 20 mm/s x 1 ms is 0.0125 of a ratio at 2 N)
  const std::size_t back = std::min<std::size_t>(at, kRampTicks);
  const double rise = back > 0 ? (ratio(at) - ratio(at - back)) / static_cast<double>(back) : 0.0;
  return ratio(at) + 0.5 * std::max(rise, 0.0);
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
    if (const double peak = breakaway_ratio(s, length, stroke_surface(s)); peak > -1e300)
      breakaway.push_back(peak);
    if (const auto slid = sliding_ratio(s, 0.5 * length, 0.95 * length)) sliding.push_back(*slid);
  }
  // the contour past its first quarter
  const double circle = 2.0 * kPi * o.contour_radius_m;
  if (const auto slid = sliding_ratio(slides.contour, 0.25 * circle, std::numeric_limits<double>::infinity())) sliding.push_back(*slid);
  if (!breakaway.empty()) e.friction_static = std::max(0.0, mean(breakaway));
  if (!sliding.empty()) e.friction_dynamic = std::max(0.0, mean(sliding));
}

}  // namespace uh::exploration
