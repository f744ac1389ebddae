// Friction per contact patch on real packed shapes: a 1 cm packed ball pinched between the two
// walls of one object (two packed slabs facing each other, each pressed 1.5 mm into the ball), so
// that the walls' penalty forces cancel while each wall's friction must not. The walls' normal
// forces are summed by hand over each wall's leaves.
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "lens_reference.hpp"
#include "scene_test_support.hpp"
#include "uh/collette/collision_world.hpp"
#include "uh/collette/sphere_tree_builder.hpp"
#include "uh/controllers/force_controller.hpp"
#include "uh/controllers/scene.hpp"
#include "uh/forcecomp/contact_patches.hpp"
#include "uh/forcecomp/wrench_model.hpp"

namespace uh::controllers {
namespace {

constexpr double kStiffness = 2.0e4;  // N/m^2
constexpr double kMuStatic = 0.6;
constexpr double kMuDynamic = 0.4;
constexpr double kStick = 500.0;   // N/m, SurfaceStageOptions' default
constexpr double kPeriod = 1e-3;   // 1 kHz haptic ticks
constexpr int kTicksPerFrame = 4;  // a collision frame every 4 ticks (250 Hz): multi-rate

struct Groove {
  std::vector<Sphere> walls[2];  // each wall's leaves, world frame
  std::shared_ptr<const collette::SphereTree> groove;
  std::shared_ptr<const collette::SphereTree> ball;
  double coverage_product = 1.0;
};

// two 5 mm slabs facing each other across y = 0, their faces `half_gap` from it
const Groove& groove() {
  static const Groove* g = [] {
    auto* out = new Groove;
    const auto cache = testing::fresh_cache("contact-patch");
    const auto slab = load_shape_tree(
        {.mesh = testing::test_assets() / "meshes" / "slab.obj", .spheres = 400, .meters_per_unit = 0.01},
        cache);
    const auto ball = load_shape_tree(
        {.mesh = testing::test_assets() / "meshes" / "ball.obj", .spheres = 100, .meters_per_unit = 0.01},
        cache);
    std::filesystem::remove_all(cache);  // the trees are in memory
    EXPECT_TRUE(slab.has_value() && ball.has_value());
    if (!slab || !ball) return out;
    // the packed ball's surface lies a little inside the mesh's: its widest leaf extent along y
    double ball_half_width = 0.0;
    for (const Sphere& s : ball->tree->leaves())
      ball_half_width = std::max(ball_half_width, double{s.y + s.radius});
    const double half_gap = ball_half_width - 0.0015;  // each wall pressed 1.5 mm into the ball
    // the slab's face is its local z = 0 with the body below: turned to face +y (at -half_gap) and -y
    const Pose poses[2] = {{quat_from_axis_angle({1, 0, 0}, -kPi / 2), {0, -half_gap, 0}},
                           {quat_from_axis_angle({1, 0, 0}, kPi / 2), {0, half_gap, 0}}};
    std::vector<Sphere> all;
    for (int w = 0; w < 2; ++w)
      for (const Sphere& s : slab->tree->leaves()) {
        const Vec3 c = transform_point(poses[w], Vec3{s.x, s.y, s.z});
        out->walls[w].push_back(
            Sphere{static_cast<float>(c.x), static_cast<float>(c.y), static_cast<float>(c.z), s.radius});
        all.push_back(out->walls[w].back());
      }
    auto tree = collette::build_sphere_tree(all);
    EXPECT_TRUE(tree.has_value());
    out->groove = std::make_shared<const collette::SphereTree>(std::move(*tree));
    out->ball = ball->tree;
    out->coverage_product = slab->coverage * ball->coverage;
    return out;
  }();
  return *g;
}

// |penalty force| of one wall on the ball at `position`, summed by hand over every leaf pair
double wall_normal_force(int wall, const Vec3& position) {
  const Groove& g = groove();
  Vec3 f{};
  for (const Sphere& o : g.walls[wall])
    for (const Sphere& t : g.ball->leaves()) {
      const Vec3 d = position + Vec3{t.x, t.y, t.z} - Vec3{o.x, o.y, o.z};
      const auto lens = uh::test::lens_reference(norm(d), o.radius, t.radius);
      if (lens.volume > 0.0) f += kStiffness / g.coverage_product * lens.area * normalized(d);
    }
  return norm(f);
}

// The groove in a world, the ball as the tool, a ForceController over them; ticks driven by hand.
struct Rig {
  collette::CollisionWorld world;
  collette::ObjectId groove_id = -1, ball_id = -1;
  collette::WatcherId watcher = -1;
  std::unique_ptr<ForceController> controller;
  double t = 0.0;
  int ticks = 0;

  Rig(ForceControllerOptions options, double mu_s = kMuStatic, double mu_d = kMuDynamic,
      forcecomp::ForceMode mode = forcecomp::ForceMode::k6Dof) {
    const Groove& g = groove();
    groove_id = *world.add_object({.tree = g.groove, .name = "groove"});
    ball_id = *world.add_object({.tree = g.ball, .name = "ball"});
    watcher = *world.add_collision_watcher(groove_id, ball_id);
    forcecomp::ForceComponentOptions component;
    component.mode = mode;
    component.params.damping = 0.0;
    controller = std::make_unique<ForceController>(ball_id, forcecomp::ForceComponent(component),
                                                   WorkspaceMapping{}, options);
    forcecomp::ContactMaterial material;
    material.stiffness = kStiffness;
    material.friction_static = mu_s;
    material.friction_dynamic = mu_d;
    controller->add_watched(groove_id, g.coverage_product, &material);
    controller->read_frames_of(watcher);
    controller->bind(world);
  }
  // one tick with the ball at `position` moving at `velocity`: a collision frame, then the force
  Vec3 tick(const Vec3& position, const Vec3& velocity) {
    t += kPeriod;
    world.set_pose(ball_id, Pose{{}, position});
    if (ticks++ % kTicksPerFrame == 0) world.step(t);
    haptico::DeviceState state;
    state.time_s = t;
    state.position = position;
    state.linear_velocity = velocity;
    haptico::DeviceCommand command;
    controller->on_force(state, command);
    return command.force;
  }
};

struct Mode {
  const char* name;
  ForceControllerOptions options;
};
const Mode kModes[] = {
    {"model", {}}, {"exact", {.tick_force = TickForce::kExact}}, {"held", {.multi_rate = false}}};

TEST(ContactPatches, TheTwoWallsOfAGrooveAreTwoPatchesWhoseModelsSumToTheWhole) {
  Rig rig({});
  const Groove& g = groove();
  rig.world.set_pose(rig.ball_id, Pose{});
  rig.world.step(0.0);
  ContactFrame frame;
  ASSERT_TRUE(rig.world.read_contact(rig.watcher, frame));
  ASSERT_GT(frame.pair_count, 0);
  const forcecomp::ContactPatches patches = forcecomp::find_contact_patches(frame.pairs());
  ASSERT_EQ(patches.count, 2);
  forcecomp::PenaltyInput input;
  input.stiffness = kStiffness;
  input.coverage_product = g.coverage_product;
  input.damping = 1.0;  // D too
  const forcecomp::WrenchModel whole = forcecomp::build_wrench_model(frame.pairs(), Pose{}, Pose{}, input);
  forcecomp::WrenchModel parts[2];
  for (int i = 0; i < 2; ++i)
    parts[i] = forcecomp::build_wrench_model(frame.pairs(), Pose{}, Pose{}, input, {}, {&patches, i});
  // each patch is one wall: its force is along +y or -y and is that wall's, summed by hand
  double n_sum = 0.0;
  for (int i = 0; i < 2; ++i) {
    const Vec3 f = parts[i].wrench.force;
    EXPECT_GT(std::abs(f.y), 0.99 * norm(f));
    n_sum += norm(f);
  }
  const double n1 = wall_normal_force(0, {}), n2 = wall_normal_force(1, {});
  EXPECT_NEAR(n_sum, n1 + n2, 1e-6 * (n1 + n2));
  EXPECT_LT(norm(whole.wrench.force), 0.2 * (n1 + n2)) << "the walls' forces cancel";
  // W0, S, D and the volume sum to the whole's
  const double scale_f = n1 + n2;
  EXPECT_NEAR(norm(parts[0].wrench.force + parts[1].wrench.force - whole.wrench.force), 0.0, 1e-12 * scale_f);
  EXPECT_NEAR(norm(parts[0].wrench.torque + parts[1].wrench.torque - whole.wrench.torque), 0.0,
              1e-12 * scale_f);
  EXPECT_NEAR(parts[0].total_volume + parts[1].total_volume, whole.total_volume, 1e-12 * whole.total_volume);
  EXPECT_EQ(parts[0].pair_count + parts[1].pair_count, whole.pair_count);
  double s_max = 0.0, d_max = 0.0;
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) {
      s_max = std::max(s_max, std::abs(whole.stiffness[r][c]));
      d_max = std::max(d_max, std::abs(whole.damping[r][c]));
    }
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) {
      EXPECT_NEAR(parts[0].stiffness[r][c] + parts[1].stiffness[r][c], whole.stiffness[r][c], 1e-12 * s_max);
      EXPECT_NEAR(parts[0].damping[r][c] + parts[1].damping[r][c], whole.damping[r][c], 1e-12 * d_max);
    }
}

TEST(ContactPatches, ABallDraggedAlongAGrooveFeelsTheDynamicFrictionOfBothWalls) {
  // 2 cm along the groove at 2 cm/s; from the second half on the contact slides throughout
  const Vec3 velocity{0.02, 0, 0};
  for (const Mode& mode : kModes)
    for (const auto dof : {forcecomp::ForceMode::k6Dof, forcecomp::ForceMode::k3Dof}) {
      Rig rig(mode.options, kMuStatic, kMuDynamic, dof);
      double friction = 0.0, expected = 0.0, old_expected = 0.0;
      int samples = 0;
      for (int i = 0; i <= 1000; ++i) {
        const Vec3 p{-0.01 + 0.02 * i / 1000.0, 0, 0};
        const Vec3 f = rig.tick(p, velocity);
        if (i < 500 || i % 25 != 0) continue;
        friction += -f.x;
        const double n1 = wall_normal_force(0, p), n2 = wall_normal_force(1, p);
        expected += kMuDynamic * (n1 + n2);
        old_expected += kMuDynamic * std::abs(n2 - n1);  // the walls' forces are along -y and +y
        ++samples;
      }
      friction /= samples;
      expected /= samples;
      old_expected /= samples;
      std::printf("[ %s %s ] friction %.4f N, mu_d (N1 + N2) %.4f N, mu_d |N1 + N2| %.4f N\n", mode.name,
                  dof == forcecomp::ForceMode::k6Dof ? "6-DOF" : "3-DOF", friction, expected, old_expected);
      EXPECT_NEAR(friction, expected, 0.05 * expected) << mode.name;
      EXPECT_LT(old_expected, 0.2 * expected) << mode.name;
    }
}

TEST(ContactPatches, APinchedBallPushedBelowStaticFrictionSticksFrameAfterFrame) {
  // pushed sideways by half the breakaway force of both walls and held for 0.5 s (500 frames):
  // the stick points of both patches stay, the friction is the stick springs' k x throughout
  for (const Mode& mode : kModes) {
    Rig rig(mode.options);
    for (int i = 0; i < 50; ++i) rig.tick({}, {});
    const double n = wall_normal_force(0, {}) + wall_normal_force(1, {});
    const double push = 0.5 * kMuStatic * n;
    const double x = push / (2.0 * kStick);  // two stick springs in parallel
    double worst = 0.0;
    for (int i = 0; i < 500; ++i) {
      const Vec3 f = rig.tick({x, 0, 0}, {});
      if (i >= 10) worst = std::max(worst, std::abs(-f.x - push));
    }
    std::printf("[ %s ] push %.4f N (mu_s (N1 + N2) = %.4f N), largest deviation %.5f N\n", mode.name, push,
                kMuStatic * n, worst);
    EXPECT_LT(worst, 0.05 * push) << mode.name;
  }
}

// work done on the hand by the force around `loops` circles in the x-z plane (radius 3 mm)
double loop_work(const ForceControllerOptions& options, double mu_s, double mu_d, int loops) {
  Rig rig(options, mu_s, mu_d);
  const double radius = 0.003, omega = 2 * kPi * 2.0;  // 2 turns per second
  double work = 0.0;
  Vec3 last{};
  Vec3 force = rig.tick({}, {});
  for (int i = 1; i <= loops * 500; ++i) {
    const double a = omega * i * kPeriod;
    const Vec3 p{radius * std::sin(a), 0, radius * (1 - std::cos(a))};
    const Vec3 v{radius * omega * std::cos(a), 0, radius * omega * std::sin(a)};
    work += dot(force, p - last);  // the force held over the period, on the hand's motion
    last = p;
    force = rig.tick(p, v);
  }
  return work;
}

TEST(ContactPatches, FrictionOfTwoPatchesPutsNoEnergyIntoTheHandAroundClosedPaths) {
  for (const Mode& mode : kModes) {
    // the tool's path is imposed: the penalty's work is the same with and without friction
    const double penalty = loop_work(mode.options, 0.0, 0.0, 3);
    const double with_friction = loop_work(mode.options, kMuStatic, kMuDynamic, 3);
    std::printf("[ %s ] work of friction over 3 loops %.6f J (penalty %.6f J)\n", mode.name,
                with_friction - penalty, penalty);
    EXPECT_LT(with_friction - penalty, 0.0) << mode.name;
  }
}

}  // namespace
}  // namespace uh::controllers
