// Texture: the spectrum of the normal force ripple along each stroke axis (both strokes of the
// axis), after the breakaway (past 15 % of the stroke); the dominant spatial frequencies of the two
// axes are the components of the texture's wave vector in the stroke plane, so period = 1 / |(f_1,
// f_2)|, reported only where an axis's strokes see one sinusoid and one plane wave also explains
// the contour's ripple (plane_wave.hpp).

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numeric>
#include <optional>
#include <vector>

#include "estimators.hpp"
#include "plan.hpp"
#include "plane_wave.hpp"
#include "uh/core/least_squares.hpp"
#include "uh/core/statistics.hpp"

namespace uh::exploration {
namespace {

// the share of the contour's ripple a grating's plane wave must explain beyond the best the same
// search finds in other directions (chance), to count as periodic
constexpr double kPlaneWaveShare = 0.25;
// an axis sees a wave when one sinusoid at its peak explains more than this share of its strokes'
// ripple: a grating's ripple along a line is one sinusoid, a random texture's a sum of several
constexpr double kOneWaveShare = 0.5;
constexpr double kResampleM = 2.5e-5;  // resampling step [m]: 40 samples per millimetre

// Power of the detrended, Hann-windowed signal y(s) (uniformly resampled) at spatial frequency f [1/m]
struct Spectrum {
  std::vector<double> frequency;
  std::vector<double> power;
};

// Adds the power of one resampled residual at each frequency of `spectrum`. The window is applied
// once, and each frequency's e^(i w j) advances by one complex multiplication per sample instead of
// a sine and a cosine (the blind player's studies spent half their time in libm here); over the few
// thousand samples of a stroke the rotation's rounding stays near 1e-12 of the power.
void add_spectrum(const std::vector<double>& residual, double ds, Spectrum& spectrum) {
  const std::size_t n = residual.size();
  std::vector<double> windowed(n);
  for (std::size_t i = 0; i < n; ++i)
    windowed[i] = residual[i] * (0.5 - 0.5 * std::cos(2.0 * kPi * static_cast<double>(i) / static_cast<double>(n - 1)));
  for (std::size_t k = 0; k < spectrum.frequency.size(); ++k) {
    const double w = 2.0 * kPi * spectrum.frequency[k] * ds;
    const double step_re = std::cos(w), step_im = std::sin(w);
    double re = 0.0, im = 0.0, phase_re = 1.0, phase_im = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      re += windowed[i] * phase_re;
      im += windowed[i] * phase_im;
      const double next_re = phase_re * step_re - phase_im * step_im;
      phase_im = phase_re * step_im + phase_im * step_re;
      phase_re = next_re;
    }
    spectrum.power[k] += re * re + im * im;
  }
}

// The normal force over the sliding part of a stroke, resampled every `ds` metres, minus its line
std::vector<double> ripple_of(const Slide& s, double from_m, double to_m, double ds) {
  std::vector<double> out;
  std::size_t j = 0;
  for (double at = from_m; at <= to_m; at += ds) {
    while (j + 1 < s.travel.size() && s.travel[j + 1] < at) ++j;
    if (j + 1 >= s.travel.size()) break;
    const double span = s.travel[j + 1] - s.travel[j];
    const double u = span > 0.0 ? std::clamp((at - s.travel[j]) / span, 0.0, 1.0) : 0.0;
    out.push_back(s.normal_n[j] + u * (s.normal_n[j + 1] - s.normal_n[j]));
  }
  if (out.size() < 16) return {};
  // minus the least-squares cubic: what the hand's force loop and the shape's curvature add
  // varies over the whole stroke, the texture over millimetres
  const double half = 0.5 * static_cast<double>(out.size() - 1);
  std::vector<double> rows;
  rows.reserve(4 * out.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    const double u = (static_cast<double>(i) - half) / half;  // in [-1, 1]
    rows.insert(rows.end(), {1.0, u, u * u, u * u * u});
  }
  const core::LeastSquaresFit cubic = core::least_squares(rows, 4, out);
  if (cubic.coefficients.empty()) return {};
  const std::vector<double>& c = cubic.coefficients;
  for (std::size_t i = 0; i < out.size(); ++i) {
    const double u = (static_cast<double>(i) - half) / half;
    out[i] -= c[0] + u * (c[1] + u * (c[2] + u * c[3]));
  }
  return out;
}

// Both strokes of one axis: their ripples, the summed spectrum and the ripple's sum of squares
struct AxisRipple {
  std::vector<std::vector<double>> ripples;
  Spectrum spectrum;
  double span = 0.0;  // the window's length [m]
  double sum_sq = 0.0;
  std::size_t count = 0;
};

AxisRipple axis_ripple(const StrokeSlides& slides, const ExploreOptions& o, int axis) {
  AxisRipple a;
  const double from = 0.15 * leg_length(o, 2 * axis), to = 0.97 * leg_length(o, 2 * axis);
  a.span = to - from;
  for (double f = 2.0 / a.span; f <= 1.0 / (8.0 * kResampleM); f += 1.0 / (16.0 * a.span))
    a.spectrum.frequency.push_back(f);
  a.spectrum.power.assign(a.spectrum.frequency.size(), 0.0);
  for (int leg = 2 * axis; leg < 2 * axis + 2; ++leg) {
    const std::vector<double> r = ripple_of(slides.legs[leg], from, to, kResampleM);
    if (r.empty()) continue;
    for (double v : r) a.sum_sq += v * v;
    a.count += r.size();
    add_spectrum(r, kResampleM, a.spectrum);
    a.ripples.push_back(r);
  }
  return a;
}

// The share of the strokes' ripple (averaged over a quarter millimetre: the passivity controller's
// tick-to-tick cuts are no texture) that one sinusoid of frequency `f` [1/m] explains, its phase
// fitted stroke by stroke
double sine_share(const AxisRipple& a, double f) {
  constexpr std::size_t kHalfWidth = 5;  // samples: 0.25 mm in all
  double explained = 0.0, total = 0.0;
  for (const std::vector<double>& r : a.ripples) {
    std::vector<double> smooth(r.size()), rows;
    rows.reserve(2 * r.size());
    for (std::size_t i = 0; i < r.size(); ++i) {
      const std::size_t from = i >= kHalfWidth ? i - kHalfWidth : 0,
                        to = std::min(r.size() - 1, i + kHalfWidth);
      smooth[i] = std::accumulate(r.begin() + static_cast<std::ptrdiff_t>(from),
                                  r.begin() + static_cast<std::ptrdiff_t>(to) + 1, 0.0) /
                  static_cast<double>(to - from + 1);
      const double phase = 2.0 * kPi * f * kResampleM * static_cast<double>(i);
      rows.insert(rows.end(), {std::cos(phase), std::sin(phase)});
    }
    const core::LeastSquaresFit sine = core::least_squares(rows, 2, smooth);
    if (sine.coefficients.empty()) continue;
    double sum_sq = 0.0;
    for (double v : smooth) sum_sq += v * v;
    explained += sum_sq - sine.residual;
    total += sum_sq;
  }
  return total > 0.0 ? explained / total : 0.0;
}

// The strongest local maximum with at least 2.5 periods in the window (slower variation left over
// by the detrending leaks into the lowest frequencies and is no texture), between the grid points;
// empty unless it stands out of the packing's own grain by an order of magnitude and more
std::optional<double> spectral_peak(const Spectrum& spectrum, double span) {
  if (spectrum.power.size() < 3) return std::nullopt;
  std::size_t peak = 0;
  for (std::size_t k = 1; k + 1 < spectrum.power.size(); ++k) {
    if (spectrum.frequency[k] * span < 2.5) continue;
    if (spectrum.power[k] < spectrum.power[k - 1] || spectrum.power[k] < spectrum.power[k + 1]) continue;
    if (peak == 0 || spectrum.power[k] > spectrum.power[peak]) peak = k;
  }
  const double background = core::median(spectrum.power);
  if (!(spectrum.power[peak] > 30.0 * background) || peak == 0 || peak + 1 >= spectrum.power.size())
    return std::nullopt;
  // a parabola through the three grid points around the peak
  const double p0 = spectrum.power[peak - 1], p1 = spectrum.power[peak], p2 = spectrum.power[peak + 1];
  const double denom = p0 - 2.0 * p1 + p2;
  const double shift = denom != 0.0 ? 0.5 * (p0 - p2) / denom : 0.0;
  return spectrum.frequency[peak] + shift * (spectrum.frequency[1] - spectrum.frequency[0]);
}

}  // namespace

void estimate_texture(const StrokeSlides& slides, const ExploreTrace& trace, MaterialEstimate& e) {
  const ExploreOptions& o = trace.options;
  double sum_sq = 0.0;
  std::size_t count = 0;
  double axis_frequency[2] = {0.0, 0.0};  // [1/m], 0 = no peak along that axis
  for (int axis = 0; axis < 2; ++axis) {
    const AxisRipple a = axis_ripple(slides, o, axis);
    sum_sq += a.sum_sq;
    count += a.count;
    if (a.count == 0) continue;
    e.ripple_axis_n[axis] = std::sqrt(a.sum_sq / static_cast<double>(a.count));
    // a ripple under 0.5 % of the stroke force is the hand's own wobble, not a texture
    if (std::sqrt(a.sum_sq / static_cast<double>(a.count)) < 0.005 * o.stroke_force_n) continue;
    if (const auto f = spectral_peak(a.spectrum, a.span)) {
      e.period_axis_m[axis] = 1.0 / *f;
      e.sine_share_axis[axis] = sine_share(a, *f);
      if (e.sine_share_axis[axis] > kOneWaveShare) axis_frequency[axis] = *f;
    }
  }
  if (count > 0) e.texture_ripple_n = std::sqrt(sum_sq / static_cast<double>(count));
  if (axis_frequency[0] > 0.0 || axis_frequency[1] > 0.0) {
    // a grating is one plane wave over the whole surface: the wave vector the strokes found must
    // also explain the ripple along the contour, a third path, better than the same search does
    // in any other direction; a random texture (or a packing's grain) has its strongest component
    // differ from path to path, and then has no period
    const double f_low = 2.5 / (0.82 * std::min(leg_length(o, 0), leg_length(o, 2)));
    const PlaneWaveFit fit = fit_plane_wave(slides.contour, trace.stroke_axes, axis_frequency, f_low,
                                            e.stiffness_n_per_mm.value_or(0.0) * 1e3);
    e.texture_wave_share = fit.share - fit.chance;
    if (e.texture_wave_share >= kPlaneWaveShare) e.texture_period_m = 1.0 / std::hypot(fit.f1, fit.f2);
  }
}

}  // namespace uh::exploration
