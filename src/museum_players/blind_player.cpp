#include "uh/museum_players/blind_player.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numeric>

#include <fmt/format.h>

#include "uh/collette/ist_cache.hpp"
#include "uh/collette/sphere_tree_builder.hpp"
#include "uh/controllers/session_model.hpp"
#include "uh/core/least_squares.hpp"
#include "uh/core/split_mix.hpp"
#include "uh/core/statistics.hpp"

namespace uh::museum_players {

using exploration::ContourPath;
using exploration::ExploreOptions;
using exploration::ExplorePhase;
using exploration::ExploreSite;
using exploration::ExploreTrace;

const char* to_string(Verdict verdict) { return verdict == Verdict::genuine ? "genuine" : "forgery"; }

bool FeatureDifference::differs() const {
  return difference > threshold && (!p_value || *p_value < kRankTestLevel);
}

namespace {

constexpr double kStrokeStepM = 0.00025;  // surface tracks along strokes: a sample every 0.25 mm
constexpr int kAroundSamples = 720;       // around the piece: every half degree
// The stiffness presses on the top: how many, on a ring of what radius, read at what depth, and the
// force at which a press stops short of it. Through the proxy the force is the spring the stylus
// feels times the depth past first contact (the proxy stays on the surface), whatever the packing
// under it: a finger's pad (a wider ball) would feel the same spring capped by the coupling.
constexpr int kTopPresses = 12;
constexpr double kTopPressRingsM[2] = {0.004, 0.008};  // every other press on the outer ring
constexpr double kPressReadDepthM = 0.0008;
constexpr double kPressMaxForceN = 20.0;
constexpr double kSlideForceN = 1.5;   // normal force held on the survey's long strokes and contours
constexpr double kEdgeClearM = 0.006;  // side contours stay this far from the base and the top

struct Bounds {
  Vec3 lo{1e300, 1e300, 1e300};
  Vec3 hi{-1e300, -1e300, -1e300};
};

Bounds world_bounds(const collette::SphereTree& tree, const Pose& pose) {
  Bounds b;
  for (const Sphere& s : tree.leaves()) {
    const Vec3 c = transform_point(
        pose, Vec3{static_cast<double>(s.x), static_cast<double>(s.y), static_cast<double>(s.z)});
    const double r = static_cast<double>(s.radius);
    b.lo = {std::min(b.lo.x, c.x - r), std::min(b.lo.y, c.y - r), std::min(b.lo.z, c.z - r)};
    b.hi = {std::max(b.hi.x, c.x + r), std::max(b.hi.y, c.y + r), std::max(b.hi.z, c.z + r)};
  }
  return b;
}

// The press's stiffness [N/mm] read at `depth` past first contact: the force there (along the
// press's mean force direction) over the depth. Through the proxy it is the spring the stylus
// feels (the proxy stays on the surface as the handle goes in), capped by the coupling's passive
// stiffness. Nothing when the press did not reach the depth.
std::optional<double> stiffness_at_depth(const ExploreTrace& trace, double depth) {
  Vec3 sum{};
  for (const auto& s : trace.samples)
    if (s.phase == ExplorePhase::kPress) sum += s.force;
  if (norm(sum) == 0.0) return std::nullopt;
  const Vec3 n = normalized(sum);
  std::optional<Vec3> touch;  // the press begins at first contact (press_depth_m: at the first force felt)
  std::optional<std::pair<double, double>> before;  // (depth, force) of the sample before
  for (const auto& s : trace.samples) {
    if (s.phase != ExplorePhase::kPress) continue;
    if (!touch) touch = s.position;
    const double d = dot(*touch - s.position, n), f = dot(s.force, n);
    if (d >= depth) {
      // between this sample and the one before it, linearly
      const double at =
          before && d > before->first
              ? before->second + (f - before->second) * (depth - before->first) / (d - before->first)
              : f;
      return at / (depth * 1e3);
    }
    before = std::pair{d, f};
  }
  return std::nullopt;
}

// One site of the survey: where and how the hand goes in, and what its tracks are called.
struct SurveySite {
  std::string name;
  ExploreOptions options;
  bool stiffness = false;  // a press whose stiffness is read
};

// fills the gaps of a resampled track (bins no sample fell in) by linear interpolation; false when empty
bool fill_gaps(std::vector<double>& v, std::vector<int>& count, bool around) {
  const std::size_t n = v.size();
  std::vector<std::size_t> known;
  for (std::size_t i = 0; i < n; ++i)
    if (count[i] > 0) known.push_back(i);
  if (known.size() < 2) return false;
  for (std::size_t k = 0; k < known.size(); ++k) {
    const std::size_t a = known[k];
    const bool last = k + 1 == known.size();
    if (last && !around) break;
    const std::size_t b = last ? known[0] + n : known[k + 1];
    for (std::size_t i = a + 1; i < b; ++i) {
      const double u = static_cast<double>(i - a) / static_cast<double>(b - a);
      v[i % n] = v[a] + u * (v[b % n] - v[a]);
    }
  }
  if (!around) {  // before the first and after the last sample: nothing was felt there
    v.erase(v.begin() + static_cast<std::ptrdiff_t>(known.back()) + 1, v.end());
    v.erase(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(known.front()));
  }
  return true;
}

// The surface the hand traced over one site's sliding stretches (the strokes and a contour around)
void add_tracks(const SurveySite& site, const ExploreTrace& trace, std::vector<SurfaceTrack>& tracks) {
  const bool side = site.options.site.from == ExploreSite::From::kSide;
  const Vec3 axis = trace.axis_point;
  const auto radial = [&axis](const Vec3& p) { return std::hypot(p.x - axis.x, p.y - axis.y); };
  const auto height = [&](const Vec3& p) { return side ? radial(p) : p.z; };
  static constexpr const char* kLegNames[2][4] = {
      {"stroke +x", "stroke -x", "stroke +y", "stroke -y"},
      {"stroke up", "stroke down", "stroke across", "stroke back"}};
  const auto& x = trace.samples;
  // a stroke down the side that slides on round the base's edge (the proxy slides at mu_d where it
  // used to stick) goes under the piece: below half the contours' clearance over the base (the
  // axis point's height) the hand is no longer on the side
  // a hand pushing more than twice the stroke's force is jammed against a rise it does not slide
  // over (the proxy held on a shelf while the handle went on): where it is tells how far it pushed
  const auto on_stroke = [&](const auto& s, std::int32_t leg) {
    return s.phase == ExplorePhase::kStroke && s.leg == leg && norm(s.force) > 0.05 &&
           norm(s.force) <= 2.0 * site.options.stroke_force_n &&
           (!side || s.position.z >= axis.z + 0.5 * kEdgeClearM);
  };
  for (std::int32_t leg = 0; leg < 4; ++leg) {
    // along the leg's axis, binned every kStrokeStepM
    const Vec3 along = trace.stroke_axes[leg / 2];
    double lo = 1e300, hi = -1e300;
    for (const auto& s : x)
      if (on_stroke(s, leg)) {
        lo = std::min(lo, dot(s.position, along));
        hi = std::max(hi, dot(s.position, along));
      }
    if (!(hi - lo > 20.0 * kStrokeStepM)) continue;
    SurfaceTrack t{.name = fmt::format("{} {}", site.name, kLegNames[side ? 1 : 0][leg]),
                   .around = false,
                   .step = kStrokeStepM,
                   .start = 0.0,
                   .height = {}};
    const auto bins = static_cast<std::size_t>((hi - lo) / kStrokeStepM) + 1;
    std::vector<double> sum(bins, 0.0);
    std::vector<int> count(bins, 0);
    for (const auto& s : x) {
      if (!on_stroke(s, leg)) continue;
      const auto i =
          std::min(bins - 1, static_cast<std::size_t>((dot(s.position, along) - lo) / kStrokeStepM));
      sum[i] += height(s.position);
      ++count[i];
    }
    for (std::size_t i = 0; i < bins; ++i)
      if (count[i] > 0) sum[i] /= count[i];
    std::size_t first = 0;
    while (first < bins && count[first] == 0) ++first;
    if (!fill_gaps(sum, count, false)) continue;
    t.start = lo + static_cast<double>(first) * kStrokeStepM;
    t.height = std::move(sum);
    tracks.push_back(std::move(t));
  }
  if (site.options.contour != ContourPath::kAroundAxis) return;
  std::vector<double> sum(kAroundSamples, 0.0);
  std::vector<int> count(kAroundSamples, 0);
  const double step = 2.0 * kPi / kAroundSamples;
  for (const auto& s : x) {
    if (s.phase != ExplorePhase::kContour || norm(s.force) <= 0.05) continue;
    double a = std::atan2(s.position.y - axis.y, s.position.x - axis.x);
    if (a < 0.0) a += 2.0 * kPi;
    const auto i = std::min<std::size_t>(kAroundSamples - 1, static_cast<std::size_t>(a / step));
    sum[i] += radial(s.position);
    ++count[i];
  }
  for (int i = 0; i < kAroundSamples; ++i)
    if (count[i] > 0) sum[i] /= count[i];
  // most of the way round, or it did not go round
  if (std::count_if(count.begin(), count.end(), [](int c) { return c > 0; }) < kAroundSamples * 3 / 4) return;
  if (!fill_gaps(sum, count, true)) return;
  tracks.push_back({.name = fmt::format("{} around", site.name),
                    .around = true,
                    .step = step,
                    .start = 0.0,
                    .height = std::move(sum)});
}

std::vector<SurveySite> plan_survey(const Bounds& b, const SurveyOptions& o) {
  std::vector<SurveySite> sites;
  const double w = b.hi.x - b.lo.x, d = b.hi.y - b.lo.y, h = b.hi.z - b.lo.z;
  ExploreOptions base;
  base.seed = o.seed;
  base.haptic_hz = o.haptic_hz;
  // the proxy moves every second tick, the haptic thread sliding it between collision steps: the
  // study costs 30 % less CPU and reads the same (docs/museum.md, "Accuracy")
  base.ticks_per_collision_step = 2;
  base.stroke_turn_rad = 0.0;
  base.stroke_stops_at_edge_rad = 0.6;  // about 35 degrees: the rim of a top
  base.presses = 1;                     // the survey presses at sites of its own (below)
  base.press_depth_m.reset();           // the top's press goes to a force (the stiffness presses: to a depth)
  base.press_force_n = 3.0;
  base.strokes_through_site = false;  // each site's strokes start at the site
  // the top, as `uh explore` does it: the material
  sites.push_back({"top", base});
  // presses on a ring round the middle of the top (the judge compares the presses' ranks), off the
  // axes along which ridges and grooves run
  for (int k = 0; k < kTopPresses; ++k) {
    ExploreOptions press = base;
    const double angle = kPi / kTopPresses + 2.0 * kPi * k / kTopPresses;
    press.site.offset_m[0] = kTopPressRingsM[k % 2] * std::cos(angle);
    press.site.offset_m[1] = kTopPressRingsM[k % 2] * std::sin(angle);
    press.stroke_legs = 0;
    press.contour = ContourPath::kNone;
    press.taps = 0;
    press.press_depth_m = kPressReadDepthM + 0.00005;
    press.press_force_n = kPressMaxForceN;
    sites.push_back({fmt::format("top press {}", k + 1), press, true});
  }
  const bool flat = h < 0.5 * std::min(w, d);
  const bool round = std::fabs(w - d) < 0.1 * std::max(w, d);
  ExploreOptions slide = base;
  slide.stroke_force_n = kSlideForceN;
  slide.taps = 0;
  slide.contour = ContourPath::kNone;
  if (flat) {  // long strokes over the top, from near one corner along x and along y
    ExploreOptions raster = slide;
    raster.site.offset_m[0] = -0.3 * w;
    raster.site.offset_m[1] = -0.3 * d;
    raster.stroke_length_m = 0.6 * w;
    raster.second_stroke_length_m = 0.6 * d;
    sites.push_back({"top raster", raster});
  }
  if (round) {  // level contours round the side at heights every ring_spacing_m, strokes up and down it
    const double span = h - 2.0 * kEdgeClearM;
    const int rings = span > 0.0 ? static_cast<int>(span / o.ring_spacing_m) + 1 : 1;
    for (int k = 0; k < rings; ++k) {
      const double z = rings == 1 ? 0.5 * h : 0.5 * h + (k - 0.5 * (rings - 1)) * o.ring_spacing_m;
      ExploreOptions ring = slide;
      ring.site.from = ExploreSite::From::kSide;
      ring.site.height_fraction = z / h;
      ring.contour = ContourPath::kAroundAxis;
      ring.contour_speed_m_per_s = 0.04;
      ring.stroke_legs = 0;
      ring.stroke_stops_at_edge_rad.reset();  // up a side that bulges and narrows
      const double up = (h - kEdgeClearM) - z;
      if (k == 0 && up > 0.01) {
        ring.stroke_legs = 2;
        ring.stroke_length_m = up;
      }
      sites.push_back({fmt::format("side {:.0f} mm", z * 1e3), ring});
    }
  }
  return sites;
}

}  // namespace

Result<PieceSurvey> survey_piece(const controllers::SceneObject& piece, const SurveyOptions& options,
                                 const std::filesystem::path& cache_dir) {
  // the stylus: one ball
  const Sphere ball{0.f, 0.f, 0.f, static_cast<float>(options.tool_radius_m)};
  auto tool_tree = collette::build_sphere_tree(std::span<const Sphere>(&ball, 1));
  if (!tool_tree) return tool_tree.error();
  const auto tip = std::make_shared<const collette::SphereTree>(std::move(*tool_tree));
  controllers::Scene scene = museum_artifacts::table_scene(piece, tip, options.haptic_hz);
  // the piece's tree compiled once; each site's exploration reuses it (its proxy rests on the
  // piece's mesh surface, loaded there, as the station's does)
  collette::IstCache cache(cache_dir);
  auto model = controllers::compile(scene, cache, {.surfaces = false});
  if (!model) return Error{fmt::format("{}: {}", piece.name, model.error().message)};
  const controllers::CompiledShape& piece_shape = (*model)->objects[0];
  scene.objects[0].shape.tree = piece_shape.tree;
  scene.objects[0].shape.coverage = piece_shape.coverage;

  controllers::SessionOptions session;
  session.cache_dir = cache_dir;
  PieceSurvey survey;
  for (SurveySite& site : plan_survey(world_bounds(*piece_shape.tree, piece.pose), options)) {
    site.options.max_seconds = std::max(1.0, options.max_piece_seconds - survey.simulated_s);
    auto explored = exploration::explore_scene(scene, piece.name, site.options, session);
    if (!explored) return Error{fmt::format("{} ({}): {}", piece.name, site.name, explored.error().message)};
    const exploration::ObjectExploration& e = explored->front();
    if (site.name == "top") survey.material = e.estimate;
    if (site.stiffness)
      if (const auto k = stiffness_at_depth(e.trace, kPressReadDepthM))
        survey.site_stiffness.emplace_back(site.name, *k);
    add_tracks(site, e.trace, survey.tracks);
    survey.simulated_s += e.simulated_s;
    survey.haptic_ticks += e.haptic_ticks;
    if (survey.simulated_s >= options.max_piece_seconds) break;
  }
  return survey;
}

namespace {

constexpr double kSurfaceFloorM = 0.0003;  // a surface difference under 0.3 mm is not told apart
// nor stiffness under 25 % (a hand's Weber fraction for stiffness is about 23 %, Jones and Hunter 1990)
constexpr double kStiffnessFloor = 0.25;
constexpr double kFrictionFloor = 0.10;      // nor friction under 10 % (half of what a hand tells apart)
constexpr double kNoiseMargin = 2.0;         // a difference must exceed twice the reference's own spread
constexpr double kShiftSearchM = 0.003;      // strokes: the piece may sit up to 3 mm off the reference
constexpr std::size_t kStrokeSmoothing = 4;  // samples (1 mm) averaged before the largest difference
constexpr std::size_t kAroundSmoothing = 3;  // samples (1.5 degrees) around
// A contour holds only the level part of the force: where the side leans back by more than about
// 37 degrees (a shelf, a foot, a flaring cup) the hand slides up and down it as it circles and the
// trace tells where the hand went, not the piece. A side contour is compared only where the side's
// profile (the reference's stroke up) turns in or out by less than kContourSteepest per unit of
// height across kSteepWindowM either side of its height, and a side stroke only where it rises
// more steeply than 45 degrees.
constexpr double kContourSteepest = 0.75;
constexpr double kStrokeSteepest = 1.0;
constexpr double kSteepWindowM = 0.002;

// a - b across b's slope (where the surface is steep, a little shift along the way is a large
// difference of height but a small one across), minus its least-squares line (a piece standing a
// little off, or tilted, moves whole tracks); the line is fitted over the samples `compared` keeps
// (all when empty), and the others are 0 (what is left out must not tilt what is kept)
std::vector<double> detrended_difference(const double* a, const double* b, std::size_t n, double step,
                                         const std::vector<bool>& compared = {}) {
  const auto kept = [&compared](std::size_t i) { return compared.empty() || compared[i]; };
  std::vector<double> d(n);
  double mx = 0.0, my = 0.0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double slope = n < 3 ? 0.0 : (b[std::min(i + 1, n - 1)] - b[i > 0 ? i - 1 : 0]) / (2.0 * step);
    d[i] = (a[i] - b[i]) / std::sqrt(1.0 + slope * slope);
    if (!kept(i)) continue;
    mx += static_cast<double>(i);
    my += d[i];
    ++count;
  }
  if (count == 0) return std::vector<double>(n, 0.0);
  mx /= static_cast<double>(count);
  my /= static_cast<double>(count);
  // the line's slope, fitted in the centred variables
  std::vector<double> u, v;
  for (std::size_t i = 0; i < n; ++i) {
    if (!kept(i)) continue;
    u.push_back(static_cast<double>(i) - mx);
    v.push_back(d[i] - my);
  }
  const core::LeastSquaresFit line = core::least_squares(u, 1, v);
  const double slope = line.coefficients.empty() ? 0.0 : line.coefficients[0];
  for (std::size_t i = 0; i < n; ++i) d[i] = kept(i) ? d[i] - (my + slope * (static_cast<double>(i) - mx)) : 0.0;
  return d;
}

// the largest |v| averaged over `width` neighbouring samples (a ridge or a dent spans millimetres;
// a single sample's jolt, where the hand lost the surface for a moment, does not count)
double largest_abs(const std::vector<double>& v, std::size_t width, bool around) {
  double m = 0.0;
  const std::size_t n = v.size();
  if (n < width) return 0.0;
  for (std::size_t i = 0; i + (around ? 0 : width) <= (around ? n - 1 : n); ++i) {
    double sum = 0.0;
    for (std::size_t k = 0; k < width; ++k) sum += v[(i + k) % n];
    m = std::max(m, std::fabs(sum / static_cast<double>(width)));
  }
  return m;
}

double mean_square(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x * x;
  return v.empty() ? 0.0 : s / static_cast<double>(v.size());
}

// The largest difference between two tracks of the same stretch after the best alignment: strokes
// shifted along their axis by up to kShiftSearchM, contours around turned by any angle (the piece
// may stand turned), each minus what a piece standing off-centre adds (a line; around: the mean
// and the first harmonic). Negative when they do not overlap enough to compare.
double surface_difference(const SurfaceTrack& a, const SurfaceTrack& b, bool wall_only = false) {
  if (a.around != b.around || a.height.empty() || b.height.empty()) return -1.0;
  if (a.around) {
    const std::size_t n = a.height.size();
    if (b.height.size() != n) return -1.0;
    double best = 1e300, best_largest = -1.0;
    std::vector<double> d(n);
    for (std::size_t shift = 0; shift < n; ++shift) {
      double c0 = 0.0, c1 = 0.0, s1 = 0.0;
      for (std::size_t i = 0; i < n; ++i) {
        d[i] = a.height[i] - b.height[(i + shift) % n];
        const double angle = 2.0 * kPi * static_cast<double>(i) / static_cast<double>(n);
        c0 += d[i];
        c1 += d[i] * std::cos(angle);
        s1 += d[i] * std::sin(angle);
      }
      c0 /= static_cast<double>(n);
      c1 *= 2.0 / static_cast<double>(n);
      s1 *= 2.0 / static_cast<double>(n);
      for (std::size_t i = 0; i < n; ++i) {
        const double angle = 2.0 * kPi * static_cast<double>(i) / static_cast<double>(n);
        d[i] -= c0 + c1 * std::cos(angle) + s1 * std::sin(angle);
      }
      const double ms = mean_square(d);
      if (ms < best) {
        best = ms;
        best_largest = largest_abs(d, kAroundSmoothing, true);
      }
    }
    return best_largest;
  }
  // strokes: sample i of a is at a.start + i step; trim a millimetre at each end (the start from rest)
  const auto trim = static_cast<std::ptrdiff_t>(0.001 / a.step);
  const auto shifts = static_cast<std::ptrdiff_t>(kShiftSearchM / a.step);
  const auto offset = static_cast<std::ptrdiff_t>(std::lround((a.start - b.start) / a.step));
  const auto na = static_cast<std::ptrdiff_t>(a.height.size()),
             nb = static_cast<std::ptrdiff_t>(b.height.size());
  const std::ptrdiff_t need = std::max<std::ptrdiff_t>(40, std::min(na, nb) / 2);
  double best = 1e300, best_largest = -1.0;
  for (std::ptrdiff_t s = -shifts; s <= shifts; ++s) {
    // a[i] against b[i + offset + s]
    const std::ptrdiff_t k = offset + s;
    const std::ptrdiff_t from = std::max(trim, trim - k), to = std::min(na - trim, nb - trim - k);
    if (to - from < need) continue;
    const auto n = static_cast<std::size_t>(to - from);
    std::vector<bool> compared;
    if (wall_only) {
      // only where both surfaces rise more steeply than they turn in or out (a wall, not a shelf
      // nor an overhang: a hand stroking up under a flaring cup sticks there now and then, and its
      // trace rises straight up inside the flare, or follows it, as the friction cone lets it)
      const auto w = static_cast<std::ptrdiff_t>(0.001 / b.step);
      const auto leans = [w](const SurfaceTrack& t, std::ptrdiff_t j) {
        const auto n_t = static_cast<std::ptrdiff_t>(t.height.size());
        const std::ptrdiff_t lo = std::max<std::ptrdiff_t>(0, j - w), hi = std::min(n_t - 1, j + w);
        return hi > lo && std::fabs(t.height[static_cast<std::size_t>(hi)] - t.height[static_cast<std::size_t>(lo)]) >
                              kStrokeSteepest * static_cast<double>(hi - lo) * t.step;
      };
      compared.resize(n);
      for (std::size_t i = 0; i < n; ++i) {
        const std::ptrdiff_t j = from + static_cast<std::ptrdiff_t>(i);
        compared[i] = !leans(b, j + k) && !leans(a, j);
      }
    }
    const std::vector<double> d =
        detrended_difference(a.height.data() + from, b.height.data() + from + k, n, a.step, compared);
    const double ms = mean_square(d);
    if (ms < best) {
      best = ms;
      best_largest = largest_abs(d, kStrokeSmoothing, false);
    }
  }
  return best_largest;
}

const SurfaceTrack* find_track(const PieceSurvey& survey, const std::string& name) {
  for (const SurfaceTrack& t : survey.tracks)
    if (t.name == name) return &t;
  return nullptr;
}

// The side's profile as the hand traced it going up (distance from the centre line by height), or null
const SurfaceTrack* side_profile(const PieceSurvey& survey) {
  for (const SurfaceTrack& t : survey.tracks)
    if (t.name.rfind("side", 0) == 0 && t.name.ends_with("stroke up")) return &t;
  return nullptr;
}

// Whether the profile turns in or out by more than kContourSteepest per unit of height across
// kSteepWindowM either side of `z` (end to end: a trace's grain is not a shelf); true where the
// profile does not reach
bool shelf_near(const SurfaceTrack& profile, double z) {
  const auto n = static_cast<std::ptrdiff_t>(profile.height.size());
  const auto at = [&](double zz) {
    return static_cast<std::ptrdiff_t>(std::lround((zz - profile.start) / profile.step));
  };
  const std::ptrdiff_t lo = at(z - kSteepWindowM), hi = at(z + kSteepWindowM);
  if (lo < 0 || hi >= n || hi <= lo) return true;
  return std::fabs(profile.height[static_cast<std::size_t>(hi)] -
                   profile.height[static_cast<std::size_t>(lo)]) >
         kContourSteepest * static_cast<double>(hi - lo) * profile.step;
}

// the height a side contour was planned at, from its name ("side 25 mm around"), or nothing
std::optional<double> contour_height(const SurfaceTrack& t) {
  double mm = 0.0;
  if (!t.around || std::sscanf(t.name.c_str(), "side %lf mm", &mm) != 1) return std::nullopt;
  return mm * 1e-3;
}

// |a / b - 1|, or nothing when either is missing or b is not positive
std::optional<double> relative_difference(const std::optional<double>& a, const std::optional<double>& b) {
  if (!a || !b || !(*b > 0.0)) return std::nullopt;
  return std::fabs(*a / *b - 1.0);
}

}  // namespace

Judgement judge_piece(const PieceSurvey& piece, const PieceSurvey& reference,
                      const PieceSurvey& reference_again) {
  Judgement j;
  // the surface: per track, against the reference's same track
  std::vector<FeatureDifference> surface;
  const SurfaceTrack* profile = side_profile(reference);
  for (const SurfaceTrack& r : reference.tracks) {
    const SurfaceTrack* p = find_track(piece, r.name);
    const SurfaceTrack* again = find_track(reference_again, r.name);
    if (p == nullptr || again == nullptr) continue;
    // a contour round a shelf of the side tells where the hand was, not the piece
    if (const auto z = contour_height(r); z && profile != nullptr && shelf_near(*profile, *z)) continue;
    const bool side_stroke = !r.around && r.name.rfind("side", 0) == 0;
    // the piece differs only as much as it differs from the closer of the two explorations of the
    // reference (which differ from each other by the noise)
    const double to_first = surface_difference(*p, r, side_stroke),
                 to_second = surface_difference(*p, *again, side_stroke);
    const double noise = surface_difference(*again, r, side_stroke);
    if (to_first < 0.0 || to_second < 0.0 || noise < 0.0) continue;
    const double difference = std::min(to_first, to_second);
    surface.push_back({.feature = "surface",
                       .where = r.name,
                       .difference = difference * 1e3,
                       .noise = noise * 1e3,
                       .threshold = std::max(kSurfaceFloorM, kNoiseMargin * noise) * 1e3,
                       .unit = "mm",
                       .p_value = std::nullopt});
  }
  // the most telling track first
  std::sort(surface.begin(), surface.end(), [](const FeatureDifference& a, const FeatureDifference& b) {
    return a.difference / a.threshold > b.difference / b.threshold;
  });
  if (!surface.empty()) j.evidence.push_back(surface.front());
  const auto material = [&](const char* name, const std::optional<double>& p, const std::optional<double>& r,
                            const std::optional<double>& again, double floor) {
    const auto to_first = relative_difference(p, r), to_second = relative_difference(p, again);
    const auto noise = relative_difference(again, r);
    if (!to_first || !to_second || !noise) return;
    const auto difference = std::min(*to_first, *to_second);
    j.evidence.push_back({.feature = name,
                          .where = "top",
                          .difference = difference * 100.0,
                          .noise = *noise * 100.0,
                          .threshold = std::max(floor, kNoiseMargin * *noise) * 100.0,
                          .unit = "%",
                          .p_value = std::nullopt});
  };
  // stiffness: every press on the top of the piece against every press on the reference's two
  // explorations; a difference of the medians counts only when the rank test finds the presses do
  // not interleave (a press reads where the proxy rests a little differently from spot to spot).
  const auto top_presses = [](const PieceSurvey& survey) {
    std::vector<double> k;
    for (const auto& [site, value] : survey.site_stiffness)
      if (site.rfind("top press", 0) == 0) k.push_back(value);
    return k;
  };
  const std::vector<double> piece_k = top_presses(piece), first_k = top_presses(reference),
                            second_k = top_presses(reference_again);
  std::vector<double> reference_k = first_k;
  reference_k.insert(reference_k.end(), second_k.begin(), second_k.end());
  if (!piece_k.empty() && !first_k.empty() && !second_k.empty() && core::median(first_k) > 0.0 &&
      core::median(reference_k) > 0.0)
    j.evidence.push_back(
        {.feature = "stiffness",
         .where = "top presses",
         .difference = std::fabs(core::median(piece_k) / core::median(reference_k) - 1.0) * 100.0,
         .noise = std::fabs(core::median(second_k) / core::median(first_k) - 1.0) * 100.0,
         .threshold = kStiffnessFloor * 100.0,
         .unit = "%",
         .p_value = core::rank_test_p_value(piece_k, reference_k)});
  material("dynamic friction", piece.material.friction_dynamic, reference.material.friction_dynamic,
           reference_again.material.friction_dynamic, kFrictionFloor);
  const bool differs = std::any_of(j.evidence.begin(), j.evidence.end(),
                                   [](const FeatureDifference& f) { return f.differs(); });
  j.verdict = differs ? Verdict::forgery : Verdict::genuine;
  return j;
}

bool turned_on_the_table(museum_artifacts::ArtifactKind kind) {
  using museum_artifacts::ArtifactKind;
  return kind != ArtifactKind::tablet && kind != ArtifactKind::scarab;
}

Placement place_on_table(museum_artifacts::ArtifactKind kind, core::SplitMix64& deal) {
  Placement at;
  at.turn_rad = turned_on_the_table(kind) ? 2.0 * kPi * deal.uniform() : 0.0;
  at.x = (deal.uniform() - 0.5) * 0.004;
  at.y = (deal.uniform() - 0.5) * 0.004;
  return at;
}

Result<PieceSurvey> survey_form(const museum::PieceForm& form, const Placement& at,
                                const SurveyOptions& options, const std::filesystem::path& cache_dir) {
  const Pose pose{quat_from_axis_angle({0, 0, 1}, at.turn_rad), {at.x, at.y, 0.0}};
  auto object = museum_artifacts::artifact_object(form, cache_dir, form.kind, pose);
  if (!object) return object.error();
  return survey_piece(*object, options, cache_dir);
}

Result<Reference> study_reference(museum_artifacts::ArtifactKind kind, museum::Difficulty difficulty,
                                  const SurveyOptions& options, const std::filesystem::path& cache_dir,
                                  core::SplitMix64& deal, const std::function<void()>& before_each) {
  const museum::PieceForm genuine =
      museum_artifacts::piece_form(kind, difficulty, museum_artifacts::Piece::genuine);
  SurveyOptions first_options = options;
  first_options.seed = deal.next();
  if (before_each) before_each();
  auto first = survey_form(genuine, {}, first_options, cache_dir);
  if (!first) return first.error();
  // the judge's rounds have always drawn the second study in this order: its seed, then the shift
  // (y before x), then the turn
  SurveyOptions again_options = options;
  again_options.seed = deal.next();
  Placement at;
  at.y = (deal.uniform() - 0.5) * 0.004;
  at.x = (deal.uniform() - 0.5) * 0.004;
  at.turn_rad = turned_on_the_table(kind) ? 2.0 * kPi * deal.uniform() : 0.0;
  if (before_each) before_each();
  auto again = survey_form(genuine, at, again_options, cache_dir);
  if (!again) return again.error();
  return Reference{std::move(*first), std::move(*again)};
}

Result<JudgeReport> run_judge(const JudgeOptions& options) {
  using museum_artifacts::Piece;
  JudgeReport report;
  report.difficulty = options.difficulty;
  report.seed = options.seed;
  core::SplitMix64 deal{options.seed * 0x2545F4914F6CDD1Dull + 7};  // the judge's deal
  const std::filesystem::path cache =
      options.cache_dir.empty() ? controllers::default_cache_dir() : options.cache_dir;
  const std::size_t total = options.kinds.size() * 4;
  std::size_t done = 0;
  std::size_t correct = 0, judged = 0;
  for (const museum_artifacts::ArtifactKind kind : options.kinds) {
    const std::string kind_name = museum_artifacts::to_string(kind);
    const auto progress = [&] {
      if (options.progress)
        options.progress(fmt::format("{} {}", kind_name, done % 4 < 2 ? "reference" : "piece"),
                         static_cast<double>(done) / static_cast<double>(total));
      ++done;
    };
    done = static_cast<std::size_t>(&kind - options.kinds.data()) * 4;
    auto studied = study_reference(kind, options.difficulty, options.survey, cache, deal, progress);
    if (!studied) return studied.error();
    const PieceSurvey& reference = studied->first;
    const PieceSurvey& again = studied->again;
    PairResult pair;
    pair.kind = kind;
    pair.tell = museum_artifacts::tell(kind, options.difficulty).description;
    pair.material_tell = museum_artifacts::material_tell(kind, options.difficulty).description;
    const bool genuine_first = (deal.next() & 1u) == 0u;
    for (const Piece truth :
         {genuine_first ? Piece::genuine : Piece::forgery, genuine_first ? Piece::forgery : Piece::genuine}) {
      PieceResult r;
      r.truth = truth;
      const Placement at = place_on_table(kind, deal);
      r.turn_rad = at.turn_rad;
      SurveyOptions survey_options = options.survey;
      survey_options.seed = deal.next();
      progress();
      auto survey = survey_form(museum_artifacts::piece_form(kind, options.difficulty, truth), at,
                                survey_options, cache);
      if (!survey) return survey.error();
      r.judgement = judge_piece(*survey, reference, again);
      r.simulated_s = survey->simulated_s;
      report.simulated_s += survey->simulated_s;
      correct += r.correct() ? 1 : 0;
      ++judged;
      pair.pieces.push_back(std::move(r));
    }
    report.simulated_s += reference.simulated_s + again.simulated_s;
    report.pairs.push_back(std::move(pair));
  }
  if (options.progress) options.progress("done", 1.0);
  report.accuracy = judged > 0 ? static_cast<double>(correct) / static_cast<double>(judged) : 0.0;
  return report;
}

}  // namespace uh::museum_players
