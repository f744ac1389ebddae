#include "plane_wave.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numeric>
#include <optional>
#include <vector>

#include "uh/core/least_squares.hpp"

namespace uh::exploration {
namespace {

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

// A wave vector in the stroke plane: its spatial frequencies along e1, e2 [1/m]
struct Wave {
  double g1 = 0.0, g2 = 0.0;
};

Wave turned(const Wave& w, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return {c * w.g1 - s * w.g2, s * w.g1 + c * w.g2};
}

// the angle between two waves' fronts [rad], in [0, pi / 2] (k and -k are one wave)
double front_angle(const Wave& a, const Wave& b) {
  return std::fabs(std::remainder(std::atan2(a.g2, a.g1) - std::atan2(b.g2, b.g1), kPi));
}

// a wave turned this little from the one found is the same wave to the contour: over a circle of
// radius R two waves of frequency f turned by a correlate as J0(4 pi f R sin(a / 2)), past its first
// zero at 30 degrees for periods up to 6.8 mm at R = 5 mm
constexpr double kSameWaveRad = kPi / 6.0;

// The candidates the strokes' frequencies `f` give (either relative sign; an axis's frequency alone
// with the other component searched within (-f_low, f_low) in steps of `step`), all turned by `turn`
// [rad] in the stroke plane, those that land within kSameWaveRad of `avoid` (when given) left out;
// the best of them on the contour
template <class ShareOf>
PlaneWaveFit best_candidate(const ShareOf& share_of, const double (&f)[2], double f_low, double step,
                            double turn, const Wave* avoid) {
  PlaneWaveFit best;
  const auto share_at = [&](const Wave& candidate) -> std::optional<double> {
    const Wave w = turned(candidate, turn);
    if (avoid != nullptr && front_angle(w, *avoid) < kSameWaveRad) return std::nullopt;
    return share_of(w.g1, w.g2);
  };
  const auto consider = [&](const Wave& candidate) {
    const std::optional<double> share = share_at(candidate);
    if (share && *share > best.share) {
      const Wave w = turned(candidate, turn);
      best = {*share, w.g1, w.g2};
    }
  };
  if (f[0] > 0.0 && f[1] > 0.0) {
    consider({f[0], f[1]});
    consider({f[0], -f[1]});
  }
  // an axis may see no period because its apparent period is too long for a stroke (the
  // component lies within (-f_low, f_low)), and then show a slow leftover or a packing's grain
  // instead: with each axis's frequency alone, the other component is searched within
  // (-f_low, f_low), in steps that keep the phase error over the circle's radius under half a
  // radian, then finer around the best
  for (int axis = 0; axis < 2; ++axis) {
    if (!(f[axis] > 0.0)) continue;
    const auto at = [&](double g) { return axis == 0 ? Wave{f[0], g} : Wave{g, f[1]}; };
    std::optional<double> coarse;
    double found = 0.0;
    for (double g = -f_low; g <= f_low; g += step) {
      const std::optional<double> share = share_at(at(g));
      if (share && (!coarse || *share > *coarse)) coarse = share, found = g;
    }
    if (!coarse) continue;
    for (double g = found - step; g <= found + step; g += step / 8.0) consider(at(g));
  }
  return best;
}

}  // namespace

PlaneWaveFit fit_plane_wave(const Slide& contour, const Vec3 (&axes)[2], const double (&f)[2], double f_low,
                            double stiffness) {
  PlaneWaveFit best;
  if (contour.position.size() < 32) return best;
  const ContourRipple r = contour_ripple(contour, axes, stiffness);
  const core::LeastSquaresFit base = core::least_squares(r.slow, kSlowTerms, r.y);
  if (base.coefficients.empty() || !(base.residual > 0.0)) return best;
  const auto share_of = [&](double g1, double g2) { return wave_share(r, base.residual, g1, g2); };
  const double step = 0.5 / r.circle;  // a phase error of 0.5 rad over the circle's radius
  best = best_candidate(share_of, f, f_low, step, 0.0, nullptr);
  if (!(best.share > 0.0)) return best;
  // chance: what the same search finds with its candidates turned by 30 to 150 degrees (in steps
  // of 10), away from the wave found; its best over the turns. A random texture's candidate is one
  // draw among these (its slow waves fit the 5 mm circle in any direction, more so when the relief
  // is rendered whole, as through the proxy); a grating's wave explains its contour in its own
  // direction only. The same search, so that the searched component's choice is paid for too.
  const Wave found{best.f1, best.f2};
  for (int degrees = 30; degrees <= 150; degrees += 10)
    best.chance =
        std::max(best.chance, best_candidate(share_of, f, f_low, step, kPi * degrees / 180.0, &found).share);
  return best;
}

}  // namespace uh::exploration
