// The exploration's estimators on synthetic traces built from textbook laws (a ball pressed into
// a plane, Coulomb friction with a breakaway, a sine grating): what they must read back is known
// exactly, independent of the rendering that `uh explore` checks end to end (tests/cli); and where
// the hand starts, off every sphere a wide tool would meet.

#include "uh/exploration/exploration.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <span>

#include "uh/collette/sphere_tree_builder.hpp"
#include "uh/exploration/explore_scene.hpp"
#include "uh/forcecomp/material.hpp"

namespace uh::exploration {
namespace {

struct Synthetic {
  double k = 3e4;   // N/m^2
  double r = 0.01;  // ball radius [m]
  double mu_s = 0.5, mu_d = 0.3, stick = 500.0;
  double period = 0.002, ripple = 0.1;  // grating: period [m], normal force amplitude [N]
  Vec3 grating{std::cos(0.4), std::sin(0.4), 0.0};
  // when set: a random texture read as the texture stage does, the normal force times
  // (1 + h(p) / depth), instead of the grating
  const forcecomp::Texture* random = nullptr;
  double depth = 0.0016;  // [m]
  // the hand's own wobble: its force loop swaying at `wobble_hz` by `wobble` N, the same period
  // along every path at the stroke speed, but no plane wave
  double wobble = 0.0, wobble_hz = 4.0;
};

// the normal force at surface point p, time t, while sliding at the stroke force
double normal_force(const Synthetic& m, const ExploreOptions& o, const Vec3& p, double t) {
  const double wobble = m.wobble * std::sin(2 * kPi * m.wobble_hz * t);
  if (m.random != nullptr)
    return o.stroke_force_n * (1.0 + forcecomp::texture_height(*m.random, p) / m.depth) + wobble;
  return o.stroke_force_n + m.ripple * std::sin(2 * kPi * dot(m.grating, p) / m.period) + wobble;
}

// a ball pressed into a plane, F = k pi (2 r d - d^2) (the surface at z = `surface`, first touch
// at d = 0), clamped at the trace's force limit as the limit chain does, labelled as press `press`
// (-1: unnumbered, as one press alone)
void add_press(ExploreTrace& trace, double& t, double k, double r, double surface, std::int32_t press) {
  const ExploreOptions& o = trace.options;
  const double dt = 0.001;
  for (double d = -0.0005;; d += o.press_speed_m_per_s * dt) {
    const double f = std::min(d > 0.0 ? k * kPi * (2 * r * d - d * d) : 0.0, trace.force_limit_n);
    trace.samples.push_back({t += dt, {0, 0, surface + r - d}, {0, 0, f}, ExplorePhase::kPress, press});
    // as the hand does
    if (f >= press_stop_force_n(o, trace.force_limit_n) || d >= o.press_depth_m.value_or(r)) break;
  }
  for (int i = 0; i < 10; ++i)
    trace.samples.push_back({t += dt, {0, 0, surface + r}, {}, ExplorePhase::kRelease, -1});
}

ExploreTrace synthetic_trace(const Synthetic& m) {
  ExploreTrace trace;
  const ExploreOptions& o = trace.options;
  double t = 0.0;
  const double dt = 0.001;
  add_press(trace, t, m.k, m.r, 0.0, -1);
  trace.stroke_axes[0] = {1, 0, 0};
  trace.stroke_axes[1] = {0, 1, 0};
  // strokes at the stroke force with a grating ripple; friction loads a stick spring up to
  // mu_s N, then slides at mu_d N
  for (int leg = 0; leg < 4; ++leg) {
    const Vec3 dir = (leg % 2 == 0 ? 1.0 : -1.0) * trace.stroke_axes[leg / 2];
    const Vec3 start = leg % 2 == 0 ? Vec3{0, 0, m.r} : Vec3{0, 0, m.r} - dir * o.stroke_length_m;
    bool slipping = false;
    for (double s = 0.0; s <= o.stroke_length_m; s += o.stroke_speed_m_per_s * dt) {
      const Vec3 p = start + s * dir;
      const double normal = normal_force(m, o, p, t);
      double friction = m.stick * s;
      if (friction > m.mu_s * normal) slipping = true;
      if (slipping) friction = m.mu_d * normal;
      trace.samples.push_back({t += dt, p, Vec3{0, 0, normal} - friction * dir, ExplorePhase::kStroke, leg});
    }
  }
  // the contour: one circle from the start, sliding at mu_d N throughout
  const double radius = o.contour_radius_m;
  for (double angle = 0.0; angle <= 2.0 * kPi; angle += o.stroke_speed_m_per_s * dt / radius) {
    const Vec3 p = Vec3{radius * std::sin(angle), radius * (1.0 - std::cos(angle)), m.r};
    const Vec3 dir{std::cos(angle), std::sin(angle), 0.0};
    const double normal = normal_force(m, o, p, t);
    trace.samples.push_back(
        {t += dt, p, Vec3{0, 0, normal} - m.mu_d * normal * dir, ExplorePhase::kContour, -1});
  }
  return trace;
}

TEST(Exploration, EstimatorsReadBackATextbookTrace) {
  const Synthetic m;
  const MaterialEstimate e = estimate_material(synthetic_trace(m));
  ASSERT_TRUE(e.stiffness_n_per_mm.has_value());
  EXPECT_NEAR(*e.stiffness_n_per_mm, 2 * kPi * m.r * m.k * 1e-3, 0.005 * 2 * kPi * m.r * m.k * 1e-3);
  ASSERT_TRUE(e.friction_static && e.friction_dynamic);
  EXPECT_NEAR(*e.friction_static, m.mu_s, 0.02);  // the ripple moves the breakaway by a little
  EXPECT_NEAR(*e.friction_dynamic, m.mu_d, 0.005);
  ASSERT_TRUE(e.texture_period_m.has_value());
  EXPECT_NEAR(*e.texture_period_m, m.period, 0.01 * m.period);
  // the apparent periods along the axes: period / |cos|, period / |sin| of the grating's angle
  EXPECT_NEAR(e.period_axis_m[0], m.period / std::cos(0.4), 0.02 * m.period / std::cos(0.4));
  EXPECT_NEAR(e.period_axis_m[1], m.period / std::sin(0.4), 0.03 * m.period / std::sin(0.4));
  EXPECT_NEAR(e.texture_ripple_n, m.ripple / std::sqrt(2.0), 0.1 * m.ripple / std::sqrt(2.0));
  // both axes see one sinusoid, and the wave explains the contour far beyond chance (0.25 needed)
  EXPECT_GT(e.sine_share_axis[0], 0.9);
  EXPECT_GT(e.sine_share_axis[1], 0.8);
  EXPECT_GT(e.texture_wave_share, 0.5);
}

// A grating 10 degrees off the first axis: the second axis's strokes run nearly along its ridges
// (an apparent period of 11.5 mm, too long for a stroke) and see the hand's own wobble instead,
// 0.6 of the first axis's ripple and more. The wave's slow component along that axis is searched
// on the contour all the same (it was searched only under 0.6, and the pair of peaks, the grating's
// and the wobble's, gave no wave the contour has: no period).
TEST(Exploration, AGratingAlongOneStrokeAxisIsFoundPastTheHandsWobble) {
  Synthetic m;
  m.mu_s = m.mu_d = 0.0;
  m.grating = {std::cos(0.17), std::sin(0.17), 0.0};
  m.wobble = 0.05;
  const MaterialEstimate e = estimate_material(synthetic_trace(m));
  ASSERT_GT(e.period_axis_m[1], 0.0) << "the wobble's peak along the ridges";
  EXPECT_GT(e.ripple_axis_n[1], 0.6 * e.ripple_axis_n[0]);
  ASSERT_TRUE(e.texture_period_m.has_value()) << e.texture_wave_share;
  EXPECT_NEAR(*e.texture_period_m, m.period, 0.01 * m.period);
  EXPECT_GT(e.texture_wave_share, 0.5);
}

// Several presses (each at its own spot, on surfaces at different heights): each press's own
// stiffness, and their median, so that one press on an unusual spot (a packing's grain under the
// tip) does not move the estimate
TEST(Exploration, TheStiffnessIsTheMedianOfThePresses) {
  const double r = 0.01;
  const double k[] = {3e4, 2.9e4, 4.5e4, 3.1e4, 1.5e4};  // N/m^2; median 3e4
  ExploreTrace trace;
  double t = 0.0;
  for (std::int32_t press = 0; press < 5; ++press) add_press(trace, t, k[press], r, 0.001 * press, press);
  const MaterialEstimate e = estimate_material(trace);
  ASSERT_EQ(e.stiffness_per_press_n_per_mm.size(), 5u);
  for (std::size_t i = 0; i < 5; ++i)
    EXPECT_NEAR(e.stiffness_per_press_n_per_mm[i], 2 * kPi * r * k[i] * 1e-3,
                0.005 * 2 * kPi * r * k[i] * 1e-3)
        << "press " << i;
  ASSERT_TRUE(e.stiffness_n_per_mm.has_value());
  EXPECT_NEAR(*e.stiffness_n_per_mm, 2 * kPi * r * 3e4 * 1e-3, 0.005 * 2 * kPi * r * 3e4 * 1e-3);
}

// A press in to 2.5 mm and back out along the same spring, with a damper b along the normal:
// F = k pi (2 r d - d^2) + b v, v the speed into the surface (+ in, - out), never pulling
void add_damped_press(ExploreTrace& trace, double& t, double k, double r, double b, std::int32_t press) {
  const double v = trace.options.press_speed_m_per_s, dt = 0.001, deepest = 0.0025;
  const auto force = [&](double d, double speed) {
    return d > 0.0 ? std::max(0.0, k * kPi * (2 * r * d - d * d) + b * speed) : 0.0;
  };
  double d = -0.0005;
  for (; d < deepest; d += v * dt)
    trace.samples.push_back({t += dt, {0, 0, r - d}, {0, 0, force(d, v)}, ExplorePhase::kPress, press});
  for (; d > -0.0005; d -= v * dt)
    trace.samples.push_back({t += dt, {0, 0, r - d}, {0, 0, force(d, -v)}, ExplorePhase::kRelease, -1});
  for (int i = 0; i < 10; ++i) trace.samples.push_back({t += dt, {0, 0, r + 0.001}, {}, ExplorePhase::kMove, -1});
}

// The damping is read from the loop between each press and its release: each press's b, and the
// median of the presses; a spring alone (the same curve in and out) reads none.
TEST(Exploration, TheDampingIsTheLoopBetweenPressAndRelease) {
  const double r = 0.01, k = 2e4;
  const double b[] = {0.5, 0.52, 3.0, 0.48, 0.0};  // N s/m; median 0.5
  ExploreTrace trace;
  double t = 0.0;
  for (std::int32_t press = 0; press < 5; ++press) add_damped_press(trace, t, k, r, b[press], press);
  const MaterialEstimate e = estimate_material(trace);
  ASSERT_EQ(e.damping_per_press_n_s_per_m.size(), 5u);
  for (std::size_t i = 0; i < 5; ++i)
    EXPECT_NEAR(e.damping_per_press_n_s_per_m[i], b[i], 1e-3 + 1e-3 * b[i]) << "press " << i;
  ASSERT_TRUE(e.damping_n_s_per_m.has_value());
  EXPECT_NEAR(*e.damping_n_s_per_m, 0.5, 1e-3);
  // the stiffness is read from the way in alone, its damping force a constant b v there
  ASSERT_TRUE(e.stiffness_n_per_mm.has_value());

  ExploreTrace springy;
  t = 0.0;
  add_damped_press(springy, t, k, r, 0.0, 0);
  const MaterialEstimate s = estimate_material(springy);
  ASSERT_TRUE(s.damping_n_s_per_m.has_value());
  EXPECT_NEAR(*s.damping_n_s_per_m, 0.0, 1e-6);
  // a press released without contact (no way out to compare with) says nothing of the damping
  ExploreTrace one_way;
  t = 0.0;
  add_press(one_way, t, k, r, 0.0, 0);
  EXPECT_FALSE(estimate_material(one_way).damping_n_s_per_m.has_value());
}

// A stiff surface under a low force limit: pressed to a force above the limit (as a caller may
// ask), the samples the limit chain clamped read the limit, not the material, and are left out of
// the fit; pressed by default, the press stops at 90 % of the limit, short of its depth, and says
// how deep it went. On a solid (the textbook law) both read the stiffness exactly.
TEST(Exploration, APressReadsNoSampleClampedAtTheForceLimit) {
  const double k = 1.5e5, r = 0.01, limit = 6.0;    // N/m^2, m, N: 2.5 mm in asks 20.6 N
  const double reference = 2 * kPi * r * k * 1e-3;  // N/mm
  ExploreTrace clamped;
  clamped.force_limit_n = limit;
  clamped.options.press_force_n = 20.0;
  double t = 0.0;
  add_press(clamped, t, k, r, 0.0, -1);
  ASSERT_GT(std::count_if(clamped.samples.begin(), clamped.samples.end(),
                          [&](const ExploreSample& s) { return s.force.z >= limit; }),
            100)
      << "the trace must hold clamped samples for the test to mean anything";
  const MaterialEstimate e = estimate_material(clamped);
  ASSERT_TRUE(e.stiffness_n_per_mm.has_value());
  EXPECT_NEAR(*e.stiffness_n_per_mm, reference, 0.005 * reference);
  // (add_press starts 0.5 mm above the surface)
  const double air = 0.0005;
  ASSERT_TRUE(e.press_reach_m.has_value());
  EXPECT_NEAR(*e.press_reach_m, air + *clamped.options.press_depth_m, 1e-5);

  ExploreTrace stopped;
  stopped.force_limit_n = limit;
  t = 0.0;
  add_press(stopped, t, k, r, 0.0, -1);
  const auto last_press =
      std::find_if(stopped.samples.rbegin(), stopped.samples.rend(),
                   [](const ExploreSample& s) { return s.phase == ExplorePhase::kPress; });
  ASSERT_NE(last_press, stopped.samples.rend());
  EXPECT_NEAR(last_press->force.z, 0.9 * limit, 0.1) << "the press stops at 90 % of the limit";
  const MaterialEstimate s = estimate_material(stopped);
  ASSERT_TRUE(s.stiffness_n_per_mm.has_value());
  EXPECT_NEAR(*s.stiffness_n_per_mm, reference, 0.005 * reference);
  // where k pi (2 r d - d^2) reaches 90 % of the limit
  const double reach = r - std::sqrt(r * r - 0.9 * limit / (kPi * k));
  ASSERT_TRUE(s.press_reach_m.has_value());
  EXPECT_NEAR(*s.press_reach_m, air + reach, 2 * stopped.options.press_speed_m_per_s * 0.001);
}

TEST(Exploration, ASmoothFrictionlessTraceHasNoFrictionAndNoPeriod) {
  Synthetic m;
  m.mu_s = m.mu_d = 0.0;
  m.ripple = 0.0;
  const MaterialEstimate e = estimate_material(synthetic_trace(m));
  EXPECT_NEAR(*e.friction_static, 0.0, 1e-9);
  EXPECT_NEAR(*e.friction_dynamic, 0.0, 1e-9);
  EXPECT_FALSE(e.texture_period_m.has_value());
  EXPECT_LT(e.texture_ripple_n, 1e-9);
}

// A stationary random texture has no period: its strongest component along a stroke is not a
// wave the contour sees too. Its ripple is the normal force times the RMS height over the depth,
// h / depth, of the height's components short enough for a stroke (the cubic taken out of each
// stroke removes the longer ones): for a Gaussian correlation of length l the height along a line
// has the spectral density S(f) = sigma^2 sqrt(2 pi) l exp(-2 pi^2 l^2 f^2), and the strokes keep
// about what lies above 2.5 periods per analysed stroke length, f_low. The reference integrates
// S numerically above f_low.
TEST(Exploration, ARandomTextureHasNoPeriodAndRipplesWithItsRoughness) {
  const ExploreOptions o;
  const double sigma = 3e-5, l = 1e-3;
  const double span = (0.97 - 0.15) * o.stroke_length_m, f_low = 2.5 / span;
  double kept = 0.0;  // the share of sigma^2 above f_low (both signs of f), by the midpoint rule
  const double df = 0.05;
  for (double f = f_low + 0.5 * df; f < 20.0 / l; f += df)
    kept += 2.0 * std::sqrt(2.0 * kPi) * l * std::exp(-2.0 * kPi * kPi * l * l * f * f) * df;
  double ratio_sum = 0.0;
  const std::uint64_t seeds[] = {7, 8, 9, 10, 11, 12};
  for (const std::uint64_t seed : seeds) {
    const forcecomp::Texture rough = forcecomp::make_random_texture(sigma, l, seed);
    const forcecomp::Texture rougher = forcecomp::make_random_texture(2.0 * sigma, l, seed);
    Synthetic m;
    m.random = &rough;
    const MaterialEstimate e = estimate_material(synthetic_trace(m));
    EXPECT_FALSE(e.texture_period_m.has_value())
        << "seed " << seed << ": " << e.texture_period_m.value_or(0.0);
    EXPECT_LT(e.texture_wave_share, 0.15) << "seed " << seed << ": 0.25 makes a period";
    m.random = &rougher;
    const MaterialEstimate twice = estimate_material(synthetic_trace(m));
    EXPECT_NEAR(twice.texture_ripple_n, 2.0 * e.texture_ripple_n, 1e-6)
        << "the ripple is linear in the roughness";
    ratio_sum += e.texture_ripple_n / (o.stroke_force_n * sigma / m.depth * std::sqrt(kept));
  }
  // one realisation of 64 waves varies; their mean follows the spectrum
  EXPECT_NEAR(ratio_sum / std::size(seeds), 1.0, 0.25);
}

TEST(Exploration, AnEmptyTraceGivesNoEstimates) {
  const MaterialEstimate e = estimate_material(ExploreTrace{});
  EXPECT_FALSE(e.stiffness_n_per_mm || e.friction_static || e.friction_dynamic || e.texture_period_m);
}

// A wide tool coming down over a gap in the object's spheres starts 3 mm off every sphere it would
// meet, not only the one under its tip: through the proxy, a tool that begins inside an object
// keeps no side, follows the hand in with zero force and never touches it
TEST(Exploration, AWideToolOverAGapInThePackingStartsOffItAndTouchesItThroughTheProxy) {
  // two tall spheres either side of a low one under the site: a 10 mm pad 3 mm over the low one
  // would overlap both tall ones
  const Sphere object_spheres[3] = {{-0.012f, 0.f, 0.f, 0.01f}, {0.012f, 0.f, 0.f, 0.01f}, {0.f, 0.f, -0.002f, 0.004f}};
  const Sphere pad{0.f, 0.f, 0.f, 0.01f};
  auto object = collette::build_sphere_tree(std::span<const Sphere>(object_spheres, 3));
  auto tool = collette::build_sphere_tree(std::span<const Sphere>(&pad, 1));
  ASSERT_TRUE(object.has_value() && tool.has_value());
  controllers::Scene scene;
  scene.name = "gap";
  scene.source = "a packing with a gap";
  controllers::SceneObject gap;
  gap.name = "gap";
  gap.shape.tree = std::make_shared<const collette::SphereTree>(std::move(*object));
  scene.objects = {gap};
  scene.watch = {"gap"};
  scene.tool().shape.tree = std::make_shared<const collette::SphereTree>(std::move(*tool));
  scene.force.proxy.enabled = true;
  ExploreOptions o;
  o.presses = 1;
  o.stroke_legs = 0;
  o.contour = ContourPath::kNone;
  o.taps = 0;
  o.max_seconds = 5.0;
  controllers::SessionOptions session;
  session.cache_dir = testing::TempDir();
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {  // the site moved by up to 3 mm
    o.seed = seed;
    auto explored = explore_scene(scene, "gap", o, session);
    ASSERT_TRUE(explored.has_value()) << explored.error().message;
    double pressed = 0.0;
    for (const auto& sample : explored->front().trace.samples)
      if (sample.phase == ExplorePhase::kPress) pressed = std::max(pressed, norm(sample.force));
    EXPECT_GT(pressed, 0.5) << "seed " << seed;
  }
}

}  // namespace
}  // namespace uh::exploration
