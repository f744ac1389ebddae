#include "plane_wave.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <numeric>
#include <utility>
#include <vector>

#include "uh/core/least_squares.hpp"

namespace uh::exploration {
namespace {

// an axis whose strokes ripple less than this share of the other's may see the texture's slow component only
constexpr double kSlowAxisRipple = 0.6;
constexpr std::size_t kSlowTerms = 6;  // the contour's slow part: a mean, two harmonics, a drift

// The contour's ripple as the fit reads it: per sample past the seat's transient, the slow terms'
// values (row-major, kSlowTerms a row), the smoothed unmoved force, and the position along e1, e2
struct ContourRipple {
  std::vector<double> slow;
  std::vector<double> y;
  std::vector<double> u1, u2;  // [m]
  double circle = 0.0;         // the contour's length [m]
};

ContourRipple contour_ripple(const Slide& contour, const Vec3 (&axes)[2], double stiffness) {
  ContourRipple r;
  const std::size_t n = contour.position.size();
  r.circle = contour.travel.back();
  Vec3 centre{}, contact_centre{};
  for (const Vec3& p : contour.position) centre += p;
  for (const Vec3& c : contour.contact) contact_centre += c;
  centre = centre / static_cast<double>(n);
  contact_centre = contact_centre / static_cast<double>(n);
  Vec3 normal = cross(axes[0], axes[1]);
  if (normal.z < 0.0) normal = -1.0 * normal;
  std::vector<double> unmoved(n);
  for (std::size_t j = 0; j < n; ++j)
    // the force along the stroke plane's normal, not across the motion: through a soft spring the
  // force leans a few degrees from the normal, and its magnitude's change with the lean (0.015 N at
  // 2 N and 7 degrees) drowned a grating's ripple (0.019 N through 0.19 N/mm); along the normal the
  // sum is the spring times the tool's height, the relief it rides
  unmoved[j] = dot(contour.force[j], normal) + stiffness * dot(contour.position[j] - centre, normal);
  std::vector<double> smooth(n);
  for (std::size_t j = 0, a = 0, b = 0; j < n; ++j) {
    while (contour.travel[j] - contour.travel[a] > 1.25e-4) ++a;
    while (b + 1 < n && contour.travel[b + 1] - contour.travel[j] <= 1.25e-4) ++b;
    smooth[j] = std::accumulate(unmoved.begin() + static_cast<std::ptrdiff_t>(a),
                                unmoved.begin() + static_cast<std::ptrdiff_t>(b) + 1, 0.0) /
                static_cast<double>(b - a + 1);
  }
  // the slow part: the shape and the force loop vary once or twice per turn and drift along it
  for (std::size_t j = 0; j < n; ++j) {
    if (contour.travel[j] < 0.1 * r.circle) continue;  // the seat's transient
    const Vec3 d = contour.contact[j] - contact_centre;  // the wave is where the contact is
    const double a = dot(d, axes[0]), b = dot(d, axes[1]), theta = std::atan2(b, a);
    r.slow.insert(r.slow.end(), {1.0, std::cos(theta), std::sin(theta), std::cos(2.0 * theta),
                                 std::sin(2.0 * theta), contour.travel[j] / r.circle});
    r.y.push_back(smooth[j]);
    r.u1.push_back(a);
    r.u2.push_back(b);
  }
  return r;
}

// the share of the ripple left by the slow part that the wave (g1, g2) [1/m] explains besides it
double wave_share(const ContourRipple& r, double slow_residual, double g1, double g2) {
  constexpr std::size_t kTerms = kSlowTerms + 2;
  std::vector<double> rows;
  rows.reserve(r.y.size() * kTerms);
  for (std::size_t i = 0; i < r.y.size(); ++i) {
    const double phase = 2.0 * kPi * (g1 * r.u1[i] + g2 * r.u2[i]);
    rows.insert(rows.end(), r.slow.begin() + static_cast<std::ptrdiff_t>(i * kSlowTerms),
                r.slow.begin() + static_cast<std::ptrdiff_t>((i + 1) * kSlowTerms));
    rows.insert(rows.end(), {std::cos(phase), std::sin(phase)});
  }
  const core::LeastSquaresFit full = core::least_squares(rows, kTerms, r.y);
  return full.coefficients.empty() ? 0.0 : 1.0 - full.residual / slow_residual;
}

// What a wave of the best's period explains by chance: the median share of that wave turned by 30
// to 150 degrees (in steps of 15) in the stroke plane. A grating's wave explains its contour in its
// own direction only; a random texture's slow components (periods of 4-7 mm for l = 1 mm) fit the
// 5 mm circle's ripple in any direction, more so when the relief is rendered whole, as through the
// proxy (a median of 0.10-0.21 there, 0.04-0.11 on the penalty path, whose passivity controller
// cuts the texture force on alternate ticks)
template <class ShareOf>
double chance_share(const ShareOf& share_of, const PlaneWaveFit& best) {
  const double magnitude = std::hypot(best.f1, best.f2), angle = std::atan2(best.f2, best.f1);
  if (!(magnitude > 0.0)) return 0.0;
  std::array<double, 9> turned{};
  for (std::size_t k = 0; k < turned.size(); ++k) {
    const double a = angle + kPi * static_cast<double>(k + 2) / 12.0;
    turned[k] = share_of(magnitude * std::cos(a), magnitude * std::sin(a));
  }
  std::nth_element(turned.begin(), turned.begin() + static_cast<std::ptrdiff_t>(turned.size() / 2), turned.end());
  return turned[turned.size() / 2];
}

}  // namespace

PlaneWaveFit fit_plane_wave(const Slide& contour, const Vec3 (&axes)[2], const double (&f)[2], double f_low,
                            double stiffness, const double (&ripple)[2]) {
  PlaneWaveFit best;
  if (contour.position.size() < 32) return best;
  const ContourRipple r = contour_ripple(contour, axes, stiffness);
  const core::LeastSquaresFit base = core::least_squares(r.slow, kSlowTerms, r.y);
  if (base.coefficients.empty() || !(base.residual > 0.0)) return best;
  const auto share_of = [&](double g1, double g2) { return wave_share(r, base.residual, g1, g2); };
  const auto consider = [&](double g1, double g2) {
    const double share = share_of(g1, g2);
    if (share > best.share) best = {share, g1, g2};
  };
  if (f[0] > 0.0 && f[1] > 0.0) {
    consider(f[0], f[1]);
    consider(f[0], -f[1]);
  }
  // an axis may see no period because its apparent period is too long for a stroke (the
  // component lies within (-f_low, f_low)), and then show a packing's grain instead: with each
  // axis's frequency trusted alone, the other component is searched within (-f_low, f_low), in
  // steps that keep the phase error over the circle's radius under half a radian, then finer
  // around the best (a search over all frequencies would fit a random texture's contour by
  // chance: the best of a hundred candidates)
  const double radius = r.circle / (2.0 * kPi);
  const double step = 0.5 / (2.0 * kPi * radius);
  for (int axis = 0; axis < 2; ++axis) {
    if (!(f[axis] > 0.0) || !(ripple[1 - axis] <= kSlowAxisRipple * ripple[axis])) continue;
    const auto at = [&](double g) { return axis == 0 ? std::pair{f[0], g} : std::pair{g, f[1]}; };
    PlaneWaveFit coarse;
    for (double g = -f_low; g <= f_low; g += step) {
      const auto [g1, g2] = at(g);
      const double share = share_of(g1, g2);
      if (share > coarse.share) coarse = {share, g1, g2};
    }
    const double found = axis == 0 ? coarse.f2 : coarse.f1;
    for (double g = found - step; g <= found + step; g += step / 8.0) {
      const auto [g1, g2] = at(g);
      consider(g1, g2);
    }
  }
  best.chance = chance_share(share_of, best);
  return best;
}

}  // namespace uh::exploration
