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

// The stroke's surface as the hand found it: the mean direction of the force (the surface's mean
// normal), the stroke's direction across it, and the contact's height along that normal (the
// hand's, plus its depth under the surface, the normal force over the stiffness) fitted by a
// parabola in the travel, whose derivative is the surface's slope along the stroke.
struct StrokeSurface {
  Vec3 mean_normal{};
  Vec3 along{};
  Eigen::Vector3d height{Eigen::Vector3d::Zero()};  // h = c0 + c1 u + c2 u^2, u = (travel - mid) / half
  double mid = 0.0, half = 1.0;

  // the surface's normal at sample j's travel
  Vec3 normal_at(double travel) const {
    const double slope = (height[1] + 2.0 * height[2] * (travel - mid) / half) / half;
    return normalized(mean_normal - slope * along);
  }
};

std::optional<StrokeSurface> stroke_surface(const Slide& s, double stiffness_n_per_m) {
  if (s.travel.size() < 16) return std::nullopt;
  StrokeSurface surface;
  for (const Vec3& f : s.force) surface.mean_normal += f;
  surface.mean_normal = normalized(surface.mean_normal);
  const Vec3 moved = s.position.back() - s.position.front();
  surface.along = normalized(moved - dot(moved, surface.mean_normal) * surface.mean_normal);
  surface.mid = 0.5 * (s.travel.front() + s.travel.back());
  surface.half = std::max(0.5 * (s.travel.back() - s.travel.front()), 1e-9);
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  Eigen::Vector3d atb = Eigen::Vector3d::Zero();
  for (std::size_t j = 0; j < s.travel.size(); ++j) {
    const double u = (s.travel[j] - surface.mid) / surface.half;
    const double depth = stiffness_n_per_m > 0.0 ? s.normal_n[j] / stiffness_n_per_m : 0.0;
    const Eigen::Vector3d row(1.0, u, u * u);
    ata += row * row.transpose();
    atb += (dot(s.position[j], surface.mean_normal) + depth) * row;
  }
  surface.height = ata.ldlt().solve(atb);
  if (!surface.height.allFinite() || norm(surface.along) == 0.0) return std::nullopt;
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
    const double against = s.friction_ratio[j] * s.normal_n[j];
    if (s.travel[j] < length / 3.0 && against > peak) {
      peak = against;
      at = j;
    }
  }
  if (peak <= -1e300 || !surface) return peak <= -1e300 ? peak : s.friction_ratio[at];
  const Vec3 n = surface->normal_at(s.travel[at]);
  const Vec3& f = s.force[at];
  const double pressing = dot(f, n);
  return pressing > 0.0 ? norm(f - pressing * n) / pressing : s.friction_ratio[at];
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
  const double stiffness_n_per_m = e.stiffness_n_per_mm.value_or(0.0) * 1e3;
  for (int leg = 0; leg < 4; ++leg) {
    const Slide& s = slides.legs[leg];
    if (s.travel.empty()) continue;
    const double length = leg_length(o, leg);
    if (const double peak = breakaway_ratio(s, length, stroke_surface(s, stiffness_n_per_m)); peak > -1e300)
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
