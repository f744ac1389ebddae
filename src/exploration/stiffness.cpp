// Stiffness: per press, normal force against depth while pressing in, fitted with
// F = c0 + c1 s + c2 s^2 (a round contact stiffens or softens with depth: a ball on a plane is
// exactly quadratic, k pi (2 r d - d^2)); the press's stiffness is the slope where the fit reaches
// zero force, at first touch: for a round tip 2 pi r k. The fit takes the depths from 15 % to 95 %
// of the press's (a press to a depth: the same depths for every material) or the forces from 10 %
// to 95 % of the press force (a press to a force), without the samples near the force limit
// (clamped: they read the limit, not the material). The estimate is the presses' median (each also
// reads the packing's grain under the tip).

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <vector>

#include "contact.hpp"
#include "estimators.hpp"
#include "uh/core/least_squares.hpp"
#include "uh/core/statistics.hpp"

namespace uh::exploration {
namespace {

// a sample whose force is within this share of the limit may have been clamped: the fit leaves it out
constexpr double kClampedShareOfLimit = 0.97;

// the least-squares line's slope through (x, y), fitted in the centred variables; 0 when x does not vary
double line_slope(const std::vector<double>& x, const std::vector<double>& y) {
  const double n = static_cast<double>(x.size());
  const double mx = std::accumulate(x.begin(), x.end(), 0.0) / n;
  const double my = std::accumulate(y.begin(), y.end(), 0.0) / n;
  std::vector<double> u(x.size()), v(y.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    u[i] = x[i] - mx;
    v[i] = y[i] - my;
  }
  const core::LeastSquaresFit fit = core::least_squares(u, 1, v);
  return fit.coefficients.empty() ? 0.0 : fit.coefficients[0];
}

// The slope of the least-squares parabola through (s, f) where it reaches zero force below the
// data (the first touch); the straight line's slope when the parabola has no such root.
double touch_slope(const std::vector<double>& s, const std::vector<double>& f) {
  const std::size_t n = s.size();
  const double s_mean = std::accumulate(s.begin(), s.end(), 0.0) / static_cast<double>(n);
  // in the centred variable u = s - mean (well conditioned)
  std::vector<double> rows;
  rows.reserve(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const double u = s[i] - s_mean;
    rows.insert(rows.end(), {1.0, u, u * u});
  }
  const core::LeastSquaresFit fit = core::least_squares(rows, 3, f);
  if (fit.coefficients.empty()) return line_slope(s, f);
  const double c0 = fit.coefficients[0], c1 = fit.coefficients[1], c2 = fit.coefficients[2];
  const double u_lo = *std::min_element(s.begin(), s.end()) - s_mean;
  // the root of c0 + c1 u + c2 u^2 nearest below the shallowest sample
  double root = 0.0;
  if (std::fabs(c2) < 1e-12 * std::fabs(c1)) {
    root = -c0 / c1;
  } else {
    const double disc = c1 * c1 - 4.0 * c2 * c0;
    if (disc < 0.0) return line_slope(s, f);
    const double r1 = (-c1 - std::sqrt(disc)) / (2.0 * c2), r2 = (-c1 + std::sqrt(disc)) / (2.0 * c2);
    const bool ok1 = r1 <= u_lo, ok2 = r2 <= u_lo;
    if (!ok1 && !ok2) return line_slope(s, f);
    root = ok1 && ok2 ? std::max(r1, r2) : (ok1 ? r1 : r2);
  }
  const double slope = c1 + 2.0 * c2 * root;
  return slope > 0.0 ? slope : line_slope(s, f);
}

// What one press tells: how far past first contact it went, and its stiffness [N/m]
struct PressReading {
  std::optional<double> reach_m;
  std::optional<double> stiffness_n_per_m;
};

// press `press` of `presses` (every press sample when the trace labels none)
PressReading read_press(const ExploreTrace& trace, std::int32_t press, std::int32_t presses, double press_stop_n) {
  const auto& x = trace.samples;
  const ExploreOptions& o = trace.options;
  const auto in_press = [&](const ExploreSample& s) {
    return s.phase == ExplorePhase::kPress && (presses == 0 || s.leg == press);
  };
  // the press's direction: its mean force over the samples above a fifth of its largest
  Vec3 sum{};
  double f_max = 0.0;
  for (const auto& s : x)
    if (in_press(s)) f_max = std::max(f_max, norm(s.force));
  for (const auto& s : x)
    if (in_press(s) && norm(s.force) > 0.2 * f_max) sum += s.force;
  const Vec3 n = normalized(sum);
  double first = 0.0, deepest = -1e300;
  bool any = false;
  for (const auto& s : x)
    if (in_press(s)) {
      const double d = -dot(s.position, n);
      if (!any) first = d;
      any = true;
      deepest = std::max(deepest, d);
    }
  PressReading reading;
  const double reach = deepest - first;
  if (any) reading.reach_m = reach;
  std::vector<double> depth, force;
  for (const auto& s : x) {
    if (!in_press(s)) continue;
    const double fn = dot(s.force, n), d = -dot(s.position, n);
    const bool in_band = o.press_depth_m ? d - first >= 0.15 * reach && d - first <= 0.95 * reach
                                         : fn >= 0.1 * press_stop_n && fn <= 0.95 * press_stop_n;
    const bool clamped = norm(s.force) >= kClampedShareOfLimit * trace.force_limit_n;
    if (!in_band || clamped || fn < 2.0 * kTouchN) continue;
    depth.push_back(d);
    force.push_back(fn);
  }
  if (depth.size() >= 10) reading.stiffness_n_per_m = touch_slope(depth, force);
  return reading;
}

}  // namespace

void estimate_stiffness(const ExploreTrace& trace, MaterialEstimate& e) {
  const double press_stop_n = press_stop_force_n(trace.options, trace.force_limit_n);
  std::int32_t presses = 0;
  for (const auto& s : trace.samples)
    if (s.phase == ExplorePhase::kPress) presses = std::max(presses, s.leg + 1);
  std::vector<double> reaches;
  for (std::int32_t press = 0; press < std::max(presses, 1); ++press) {
    const PressReading reading = read_press(trace, press, presses, press_stop_n);
    if (reading.reach_m) reaches.push_back(*reading.reach_m);
    if (reading.stiffness_n_per_m) e.stiffness_per_press_n_per_mm.push_back(*reading.stiffness_n_per_m * 1e-3);
  }
  if (!e.stiffness_per_press_n_per_mm.empty()) e.stiffness_n_per_mm = core::median(e.stiffness_per_press_n_per_mm);
  if (!reaches.empty()) e.press_reach_m = core::median(reaches);
}

}  // namespace uh::exploration
