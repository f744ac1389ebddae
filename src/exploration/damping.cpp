// Damping: per press, the loop between its way in and its release (loop_damping); the median of
// the presses (a grating's heights under one press can open its loop: the median passes it over).
// The presses, not the taps: they go 2.5 mm in, past any damping ramp at first touch, and the
// grain of a packing reads the same on the way in and out at one spot, so it cancels in the loop.

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "contact.hpp"
#include "estimators.hpp"
#include "uh/core/least_squares.hpp"
#include "uh/core/statistics.hpp"

namespace uh::exploration {
namespace {

// The damping of one loop into a surface and out again (samples [first, end) in contact): the
// normal force over its deeper part (60 % to 95 % of its depth past first touch: past a penalty's
// damping ramp, tool.force.damping_full_volume, for a 1 cm ball pressed 2.5 mm in) fitted by least
// squares as c0 + c1 s + c2 s^2 + b v: the curve of depth s that the way in and the way out share,
// and b times the speed into the surface v (central differences of the positions; + in, - out),
// which opens the loop between them. Samples near the turn (slower than half the median speed) say
// nothing of b and are left out; both directions must have samples. Empty without enough evidence.
std::optional<double> loop_damping(const std::vector<ExploreSample>& x, std::size_t first, std::size_t end) {
  if (first == 0 || end >= x.size() || end - first < 12) return std::nullopt;  // neighbours for the speed
  double f_max = 0.0;
  for (std::size_t k = first; k < end; ++k) f_max = std::max(f_max, norm(x[k].force));
  Vec3 sum{};
  for (std::size_t k = first; k < end; ++k)
    if (norm(x[k].force) > 0.2 * f_max) sum += x[k].force;
  const Vec3 n = normalized(sum);
  const double touch = -dot(x[first].position, n);
  double reach = 0.0;
  for (std::size_t k = first; k < end; ++k) reach = std::max(reach, -dot(x[k].position, n) - touch);
  if (!(reach > 0.0)) return std::nullopt;
  std::vector<double> speed(end - first), magnitude(end - first);
  for (std::size_t k = first; k < end; ++k) {
    const double dt = x[k + 1].time_s - x[k - 1].time_s;
    speed[k - first] = dt > 0.0 ? -dot(x[k + 1].position - x[k - 1].position, n) / dt : 0.0;
    magnitude[k - first] = std::fabs(speed[k - first]);
  }
  const double typical = core::median(magnitude);
  if (!(typical > 0.0)) return std::nullopt;
  std::vector<double> rows, force;
  int in = 0, out = 0;
  for (std::size_t k = first; k < end; ++k) {
    const double depth = -dot(x[k].position, n) - touch, v = speed[k - first];
    if (depth < 0.6 * reach || depth > 0.95 * reach || std::fabs(v) < 0.5 * typical) continue;
    // depth in units of the reach and speed in units of the typical speed: columns of one size, so
    // the normal equations stay well conditioned
    const double u = depth / reach;
    rows.insert(rows.end(), {1.0, u, u * u, v / typical});
    force.push_back(dot(x[k].force, n));
    (v > 0.0 ? in : out) += 1;
  }
  if (in < 4 || out < 4) return std::nullopt;
  const core::LeastSquaresFit fit = core::least_squares(rows, 4, force);
  if (fit.coefficients.size() != 4) return std::nullopt;
  return fit.coefficients[3] / typical;
}

}  // namespace

void estimate_damping(const ExploreTrace& trace, MaterialEstimate& e) {
  const auto& x = trace.samples;
  const auto pressing = [](const ExploreSample& s) {
    return (s.phase == ExplorePhase::kPress || s.phase == ExplorePhase::kRelease) && norm(s.force) > kTouchN;
  };
  for (std::size_t i = 0; i < x.size();) {
    if (!pressing(x[i])) {
      ++i;
      continue;
    }
    const std::size_t first = i;
    while (i < x.size() && pressing(x[i])) ++i;
    if (const auto b = loop_damping(x, first, i)) e.damping_per_press_n_s_per_m.push_back(*b);
  }
  if (!e.damping_per_press_n_s_per_m.empty()) e.damping_n_s_per_m = core::median(e.damping_per_press_n_s_per_m);
}

}  // namespace uh::exploration
