// Materials on the haptic tick: textures as height fields, Coulomb friction with a stick point,
// passivity, and the material combination rules. References are the textbook answers (a block on
// an incline, a spring-dragged block, the Gaussian correlation), not the stage's own formulas.

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "allocation_counter.hpp"
#include "uh/forcecomp/material.hpp"
#include "uh/forcecomp/surface_stage.hpp"

namespace uh::forcecomp {
namespace {

// A flat floor z = 0 (object at the origin); a point tool at height z < 0 is pressed out with a
// penalty spring of `kWall` N/m, the normal +z. The contact point is the tool's position.
constexpr double kWall = 2000.0;

struct Floor {
  SurfaceStage stage;
  Wrench penalty_at(const Vec3& p) const { return {{0, 0, p.z < 0.0 ? -kWall * p.z : 0.0}, {}}; }
  SurfaceResult tick(const Vec3& p) {
    ContactGeometry g;
    g.normal_world = {0, 0, 1};
    g.point_world = p;
    g.depth_m = std::max(0.0, -p.z);
    g.world_from_tool = {Quat{}, p};
    return stage.apply(penalty_at(p), g, p);
  }
};

ContactMaterial friction_material(double mu_s, double mu_d) {
  ContactMaterial m;
  m.friction_static = mu_s;
  m.friction_dynamic = mu_d;
  return m;
}

TEST(Texture, GratingIsTheSineAcrossItsDirection) {
  const Texture t = make_grating(0.004, 1e-4, {0, 2, 0});
  EXPECT_NEAR(texture_height(t, {0.3, 0.001, 0.7}), 1e-4, 1e-12);  // a quarter period along y
  EXPECT_NEAR(texture_height(t, {0.0, 0.003, 0.0}), -1e-4, 1e-12);
  EXPECT_NEAR(texture_height(t, {0.05, 0.004, -0.02}), 0.0, 1e-12);
}

TEST(Texture, RandomTextureHasItsRoughnessAndGaussianCorrelation) {
  // averaged over 400 surfaces (seeds) and 50 points each: RMS and correlation at lags 0.5 l,
  // l, 2 l against roughness and roughness^2 exp(-r^2 / (2 l^2))
  const double sigma = 5e-5, l = 0.002;
  const double lags[] = {0.5 * l, l, 2.0 * l};
  double sum_sq = 0.0, sum_lag[3] = {0, 0, 0};
  int n = 0;
  for (std::uint64_t seed = 1; seed <= 400; ++seed) {
    const Texture t = make_random_texture(sigma, l, seed);
    for (int i = 0; i < 50; ++i) {
      const Vec3 p{0.0013 * i, 0.0007 * i, 0.0};
      const double h = texture_height(t, p);
      sum_sq += h * h;
      for (int k = 0; k < 3; ++k) sum_lag[k] += h * texture_height(t, p + Vec3{lags[k], 0, 0});
      ++n;
    }
  }
  EXPECT_NEAR(std::sqrt(sum_sq / n), sigma, 0.03 * sigma);
  for (int k = 0; k < 3; ++k) {
    const double expected = std::exp(-lags[k] * lags[k] / (2 * l * l));
    EXPECT_NEAR(sum_lag[k] / n / (sigma * sigma), expected, 0.03) << "lag " << lags[k];
  }
  // the same seed is the same surface
  EXPECT_EQ(texture_height(make_random_texture(sigma, l, 7), {0.01, 0.02, 0.03}),
            texture_height(make_random_texture(sigma, l, 7), {0.01, 0.02, 0.03}));
}

TEST(Materials, CombinationRules) {
  ForceParams tool_force;
  tool_force.stiffness = 3e4;
  tool_force.damping = 0.5;
  // nothing set: the tool's force parameters, no friction, no texture (today's feel)
  const ContactMaterial none = combine_materials({}, {}, tool_force);
  EXPECT_EQ(none.stiffness, 3e4);
  EXPECT_EQ(none.damping, 0.5);
  EXPECT_FALSE(none.has_friction());
  EXPECT_FALSE(none.has_texture());
  Material object;
  object.has_stiffness = true;
  object.stiffness = 1e4;
  object.has_friction = true;
  object.friction_static = 0.8;
  object.friction_dynamic = 0.2;
  Material tool;
  tool.has_stiffness = true;
  tool.stiffness = 4e4;  // springs in series: 1e4 * 4e4 / 5e4 = 8e3
  tool.has_damping = true;
  tool.damping = 0.25;
  tool.has_friction = true;
  tool.friction_static = 0.2;
  tool.friction_dynamic = 0.2;
  const ContactMaterial both = combine_materials(object, tool, tool_force);
  EXPECT_DOUBLE_EQ(both.stiffness, 8e3);
  EXPECT_DOUBLE_EQ(both.damping, 0.75);
  EXPECT_DOUBLE_EQ(both.friction_static, 0.4);
  EXPECT_DOUBLE_EQ(both.friction_dynamic, 0.2);
  const ContactMaterial one = combine_materials(object, {}, tool_force);
  EXPECT_EQ(one.stiffness, 1e4);
  EXPECT_EQ(one.friction_static, 0.8);
}

TEST(SurfaceStage, WithoutFrictionOrTextureThePenaltyPassesUnchanged) {
  Floor floor{SurfaceStage(ContactMaterial{})};
  const SurfaceResult r = floor.tick({0.01, 0.0, -0.001});
  EXPECT_EQ(r.wrench.force, (Vec3{0, 0, 2.0}));
  EXPECT_EQ(r.wrench.torque, Vec3{});
}

TEST(SurfaceStage, ADraggedToolBreaksAwayAtStaticAndSlidesAtDynamicFriction) {
  Floor floor{SurfaceStage(friction_material(0.6, 0.3), {.stick_stiffness = 1000.0})};
  const double depth = 0.001;  // N = 2 N
  const double speed = 0.02, dt = 0.001;
  double peak = 0.0;
  std::vector<double> sliding;
  for (int i = 0; i < 400; ++i) {
    const SurfaceResult r = floor.tick({speed * dt * i, 0.0, -depth});
    const double ft = r.friction_force_world.x;
    EXPECT_LE(ft, 1e-12) << "friction opposes the motion";
    EXPECT_EQ(r.friction_force_world.z, 0.0);
    peak = std::max(peak, -ft);
    if (i > 200) sliding.push_back(-ft);
  }
  // breakaway at mu_s N = 1.2 N (within one tick's spring growth k v dt = 0.02 N), then mu_d N = 0.6 N
  EXPECT_NEAR(peak, 1.2, 0.021);
  for (double f : sliding) EXPECT_NEAR(f, 0.6, 1e-9);
}

// A point mass m on an incline of angle theta under gravity, pressed in by the penalty spring:
// held by friction iff tan(theta) <= mu_s; when sliding its acceleration is g (sin - mu_d cos).
struct InclineRun {
  double travelled = 0.0;   // along the slope from the end of the tilt to the end of the run [m]
  double speed_gain = 0.0;  // speed gained along the slope over that time [m/s]
};

InclineRun slide_on_incline(double theta, double mu_s, double mu_d, double seconds) {
  // the frame of the incline: x down the slope, z its normal. The slope tilts to theta over the
  // first 0.3 s (a tool set down gently), then `seconds` more are watched
  const double g = 9.81, m = 0.1, dt = 1e-4, tilt_s = 0.3;
  Floor floor{SurfaceStage(friction_material(mu_s, mu_d), {.stick_stiffness = 2000.0})};
  Vec3 x{0, 0, -m * g / kWall}, v{};
  Vec3 x_tilted{}, v_tilted{};
  const int tilt_steps = static_cast<int>(tilt_s / dt);
  const int steps = tilt_steps + static_cast<int>(seconds / dt);
  for (int i = 0; i < steps; ++i) {
    const double angle = theta * std::min(1.0, static_cast<double>(i) / tilt_steps);
    const Vec3 gravity{g * std::sin(angle), 0, -g * std::cos(angle)};
    const SurfaceResult r = floor.tick(x);
    // contact damping along the normal and in the stick spring settle the bounce of the start
    const Vec3 damping{r.sliding ? 0.0 : -4.0 * v.x, 0.0, -4.0 * v.z};
    const Vec3 a = gravity + (r.wrench.force + damping) / m;
    v += a * dt;  // semi-implicit Euler
    x += v * dt;
    if (i + 1 == tilt_steps) {
      x_tilted = x;
      v_tilted = v;
    }
  }
  return {x.x - x_tilted.x, v.x - v_tilted.x};
}

TEST(SurfaceStage, AToolHeldOnASlopeBelowTheFrictionAngleDoesNotSlide) {
  // tan(20 deg) = 0.36 < mu_s = 0.5: held; what is left is the stick spring ringing down by
  // micrometres (sliding would cover 1.2 m in that second)
  const InclineRun held = slide_on_incline(20.0 * kPi / 180.0, 0.5, 0.3, 1.0);
  EXPECT_LT(std::fabs(held.travelled), 1e-5);
  EXPECT_NEAR(held.speed_gain, 0.0, 1e-3);
  // tan(30 deg) = 0.58 > mu_s = 0.5: slides with a = g (sin - mu_d cos) = 2.36 m/s^2
  const double theta = 30.0 * kPi / 180.0;
  const InclineRun sliding = slide_on_incline(theta, 0.5, 0.3, 1.0);
  const double a = 9.81 * (std::sin(theta) - 0.3 * std::cos(theta));
  EXPECT_NEAR(sliding.speed_gain, a * 1.0, 0.03 * a);
  EXPECT_GT(sliding.travelled, 0.45 * a);
}

TEST(SurfaceStage, ASpringDraggedToolSticksAndSlipsOverAndOver) {
  // a hand drags the tool through a soft spring at constant speed: the classic stick-slip
  // oscillator; the friction force rises to mu_s N while stuck and drops at every slip
  const double m = 0.05, k_hand = 200.0, speed = 0.01, dt = 1e-4;
  Floor floor{SurfaceStage(friction_material(0.6, 0.3), {.stick_stiffness = 2000.0})};
  Vec3 x{0, 0, -0.001}, v{};
  int slips = 0;
  bool was_sliding = false;
  double peak = 0.0;
  for (int i = 0; i < 30000; ++i) {
    const double hand = speed * dt * i;
    const SurfaceResult r = floor.tick(x);
    if (r.sliding && !was_sliding) ++slips;
    was_sliding = r.sliding;
    peak = std::max(peak, -r.friction_force_world.x);
    const double fx = k_hand * (hand - x.x) + r.wrench.force.x - (r.sliding ? 0.0 : 2.0 * v.x);
    v.x += fx / m * dt;
    v.z = 0.0;
    x.x += v.x * dt;
  }
  EXPECT_GE(slips, 3) << "stick-slip repeats";
  EXPECT_NEAR(peak, 0.6 * 2.0, 0.02);
}

TEST(SurfaceStage, FrictionPutsNoEnergyIntoTheHandAroundClosedPaths) {
  // the contact point goes around a circle (1 cm radius) ten times at a varying normal force;
  // the work of the force held over each period on the motion (what a device puts into the hand)
  Floor floor{SurfaceStage(friction_material(0.8, 0.5), {.stick_stiffness = 1500.0})};
  double work = 0.0;
  Vec3 last_p{};
  Vec3 last_f{};
  const int n = 20000;
  for (int i = 0; i <= n; ++i) {
    const double a = 2 * kPi * 10.0 * i / n;
    const Vec3 p{0.01 * std::cos(a), 0.01 * std::sin(a), -0.001 * (1.5 + 0.5 * std::sin(3 * a))};
    const SurfaceResult r = floor.tick(p);
    if (i > 0) work += dot(last_f, p - last_p);
    last_p = p;
    last_f = r.friction_force_world;
  }
  EXPECT_LT(work, 0.0);
}

TEST(SurfaceStage, TextureRipplesTheNormalForceAtItsPeriodAndStaysPassive) {
  ContactMaterial m;
  m.object_texture = make_grating(0.002, 1e-4, {1, 0, 0});
  Floor floor{SurfaceStage(m)};
  // sliding at constant depth: the normal force is N (1 + h / depth), h the grating under the point
  for (int i = 0; i < 100; ++i) {
    const Vec3 p{0.0001 * i, 0.0, -0.001};
    const SurfaceResult r = floor.tick(p);
    const double h = 1e-4 * std::sin(2 * kPi * p.x / 0.002);
    EXPECT_NEAR(r.wrench.force.z, 2.0 * (1.0 + h / 0.001), 1e-9);
  }
  // a path that would harvest energy from the ripple: pressing in where the texture force is low
  // and letting out where it is high (the depth follows the grating a quarter period late)
  Floor harvest{SurfaceStage(m)};
  double work = 0.0;
  Vec3 last_p{}, last_f{};
  for (int i = 0; i <= 20000; ++i) {
    const double x = 1e-5 * i;
    const Vec3 p{x, 0.0, -0.001 - 2e-4 * std::cos(2 * kPi * x / 0.002)};
    const SurfaceResult r = harvest.tick(p);
    if (i > 0) work += dot(last_f, p - last_p);
    last_p = p;
    last_f = r.texture_force_world;
  }
  EXPECT_GT(harvest.stage.texture_drops(), 0u) << "the path does try to harvest";
  // at most the work of one tick's texture force is ever out: 0.5 * 2 N * 2e-4 m * 2 pi / 200 steps
  EXPECT_LT(work, 1e-5);
  EXPECT_LT(harvest.stage.texture_work_j(), 1e-5);
}

TEST(SurfaceStage, ThreeDofAddsNoTorqueSixDofTurnsAboutTheCentreOfMass) {
  ContactGeometry g;
  g.normal_world = {0, 0, 1};
  g.point_world = {0, 0, -0.001};
  g.depth_m = 0.001;
  SurfaceStage six(friction_material(0.5, 0.5), {.mode = ForceMode::k6Dof});
  SurfaceStage three(friction_material(0.5, 0.5), {.mode = ForceMode::k3Dof});
  const Vec3 com{0, 0, 0.05};
  const Wrench penalty{{0, 0, 2.0}, {}};
  six.apply(penalty, g, com);
  three.apply(penalty, g, com);
  g.point_world = {0.001, 0, -0.001};  // dragged 1 mm: 0.5 N of stick spring, within mu_s N = 1 N
  const SurfaceResult r6 = six.apply(penalty, g, com + Vec3{0.001, 0, 0});
  const SurfaceResult r3 = three.apply(penalty, g, com + Vec3{0.001, 0, 0});
  EXPECT_NEAR(r6.friction_force_world.x, -0.5, 1e-12);
  EXPECT_EQ(r3.wrench.torque, Vec3{});
  // the friction acts at the contact point, 5.1 cm below the centre of mass: r x F = (0, 0.051 * 0.5, 0)
  EXPECT_NEAR(r6.wrench.torque.y, 0.051 * 0.5, 1e-9);
}

TEST(SurfaceStage, ApplyDoesNotAllocate) {
  ContactMaterial m = friction_material(0.5, 0.3);
  m.object_texture = make_random_texture(5e-5, 0.002, 3);
  Floor floor{SurfaceStage(m)};
  uh::test::AllocationCounter counter;
  for (int i = 0; i < 1000; ++i) floor.tick({1e-5 * i, 0.0, -0.001});
  EXPECT_EQ(counter.count(), 0u);
}

}  // namespace
}  // namespace uh::forcecomp
