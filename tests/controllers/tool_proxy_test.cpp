// The god-object holds thin walls: a handle driven through a packed plate of 2-3 mm, flat or tilted,
// slowly or farther than the plate's thickness in one collision step, leaves the proxy on the side
// it came from, and the spring to the proxy pushes the handle back. The reference is the plate's
// true geometry (a box), not the packing or the solver: the ball's centre never comes nearer the
// plate's mid-plane than its radius plus half the thickness, less the packing's surface gap and the
// allowed penetration; and, checked by brute force over every pair of spheres, no tool sphere
// overlaps a plate sphere by more than the allowed penetration.
#include "uh/controllers/tool_proxy.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>
#include <cstdlib>
#include <string>
#include <sstream>

#include <fmt/format.h>

#include "hand_energy_support.hpp"
#include "proxy_test_support.hpp"
#include "scene_test_support.hpp"
#include "uh/collette/collision_world.hpp"
#include "uh/collette/ist_builder.hpp"
#include "uh/collette/ist_file.hpp"
#include "uh/controllers/session_model.hpp"
#include "uh/controllers/haptic_session.hpp"
#include "uh/collette/mesh_import.hpp"
#include "uh/collette/mesh_inside.hpp"
#include "uh/collette/sphere_packing.hpp"
#include "uh/collette/sphere_tree_builder.hpp"
#include "uh/forcecomp/virtual_coupling.hpp"

namespace uh::controllers {
namespace {

using testing::box_mesh;
using testing::centre_of;
using testing::deepest_overlap;
using testing::pack;
using testing::Packed;

struct WallRun {
  double closest_m = 1e9;     // nearest the ball's centre came to the plate's mid-plane (signed, + on its side)
  double deepest_m = 0.0;     // deepest sphere overlap seen (brute force, sampled steps)
  double final_push_n = 0.0;  // the spring force on the handle along the plate's normal at the end
};

// Drives the handle along the plate's normal from 2 cm in front of it to `through` behind it at
// `step_per_tick` per collision step, then holds it there; one world step per target.
WallRun drive(const Packed& plate, const Pose& world_from_plate, const Packed& ball, double step_per_tick, double through, const ToolProxyOptions& options) {
  collette::CollisionWorld world({.rate_hz = 0.0, .contact_margin = options.step_m});
  const auto plate_id = world.add_object({.tree = plate.tree, .world_from_object = world_from_plate, .is_static = true, .name = "plate"});
  const auto tool_id = world.add_object({.tree = ball.tree, .has_initial_pose = false, .name = "ball"});
  EXPECT_TRUE(plate_id && tool_id);
  EXPECT_TRUE(world.add_tool_watcher(*tool_id));
  ToolProxy proxy(world, *tool_id, *ball.tree, options, true);
  proxy.watch(*plate_id);
  proxy.bind();
  const Vec3 normal = rotate(world_from_plate.rotation, Vec3{0, 0, 1});
  const Vec3 centre = world_from_plate.position;
  WallRun run;
  Pose handle{};
  handle.rotation = world_from_plate.rotation;
  double along = 0.02;
  ProxyState state{};
  const forcecomp::VirtualCoupling spring({.stiffness = 1500.0});
  for (int i = 0; i < 2000; ++i) {
    along = std::max(along - step_per_tick, -through);
    handle.position = centre + along * normal;
    proxy.set_target(handle);
    world.step(1e-3 * i);
    if (const ProxyState* s = proxy.take()) state = *s;
    const double height = dot(state.world_from_proxy.position - centre, normal);
    run.closest_m = std::min(run.closest_m, height);
    if (i % 97 == 0 || i == 1999)
      run.deepest_m = std::max(run.deepest_m, deepest_overlap(*plate.tree, world_from_plate, *ball.tree,
                                                              state.world_from_proxy));
  }
  const Pose slid = proxy.slide(state, handle);
  run.final_push_n = dot(spring.stiffness() * (slid.position - handle.position), normal);
  return run;
}

class ThinWall : public ::testing::TestWithParam<double> {};

TEST_P(ThinWall, HoldsTheToolOnTheSideItCameFrom) {
  const double thickness = GetParam();
  const Packed plate = pack(box_mesh({0.06, 0.06, thickness}), 10000);
  constexpr double kRadius = 0.005;  // a 1 cm ball, packed
  // the ball as one sphere: a packing of a ball has it at its core, and its small spheres only add
  const auto ball_tree = collette::build_sphere_tree(std::vector<Sphere>{{0.f, 0.f, 0.f, static_cast<float>(kRadius)}});
  ASSERT_TRUE(ball_tree);
  const Packed ball{std::make_shared<const collette::SphereTree>(*ball_tree), 0.0};
  const ToolProxyOptions options{.enabled = true, .step_m = 0.002, .penetration_m = 0.0001};
  for (const double tilt_deg : {0.0, 35.0, 80.0}) {
    Pose world_from_plate;
    world_from_plate.position = {0.01, -0.02, 0.1};
    world_from_plate.rotation = quat_from_axis_angle(normalized(Vec3{1, 0.3, 0}), tilt_deg * kPi / 180.0);
    // a hand at 5 cm/s and one that moves 1 cm (more than the plate is thick) per step
    for (const double per_step : {0.00005, 0.01}) {
      const WallRun run = drive(plate, world_from_plate, ball, per_step, 0.03, options);
      const double floor = thickness / 2 + kRadius - plate.max_gap - options.penetration_m - 1e-5;
      EXPECT_GT(run.closest_m, floor) << thickness * 1e3 << " mm plate at " << tilt_deg << " deg, " << per_step
                                      << " m per step: the ball's centre came within " << run.closest_m * 1e3
                                      << " mm of the mid-plane";
      EXPECT_LT(run.deepest_m, options.penetration_m + 1e-5) << thickness * 1e3 << " mm, " << tilt_deg << " deg";
      // the handle is 3 cm behind the plate: the spring pushes it back out, far beyond a device's 8 N
      EXPECT_GT(run.final_push_n, 8.0) << thickness * 1e3 << " mm, " << tilt_deg << " deg";
    }
  }
}

INSTANTIATE_TEST_SUITE_P(TwoAndThreeMillimetres, ThinWall, ::testing::Values(0.002, 0.003));

// A 6 x 6 cm plate 3 mm thick packed with 10,000 spheres and a 1 cm ball tool of one sphere,
// watched against everything in a world stepped by hand
struct BallOverPlate {
  Packed plate = pack(box_mesh({0.06, 0.06, 0.003}), 10000);
  std::shared_ptr<const collette::SphereTree> ball = std::make_shared<const collette::SphereTree>(
      collette::build_sphere_tree(std::vector<Sphere>{{0.f, 0.f, 0.f, 0.005f}}).value());
  collette::CollisionWorld world{{.rate_hz = 0.0, .contact_margin = 0.002}};
  collette::ObjectId plate_id = world.add_object({.tree = plate.tree, .is_static = true, .name = "plate"}).value();
  collette::ObjectId tool_id = world.add_object({.tree = ball, .has_initial_pose = false, .name = "ball"}).value();
  BallOverPlate() { EXPECT_TRUE(world.add_tool_watcher(tool_id)); }
};

// The rows a step ends in contact with (ToolProxy::contact_rows: through a proxy, the session's
// contact begin and end events) count the step's own motion: a handle that jumps behind a plate and
// back puts the proxy on the plate and takes it off again, and on every step the count says
// whether the proxy then rests on the plate, judged by its height over where it came to rest.
TEST(ToolProxy, CountsTheContactOfTheStepItTook) {
  BallOverPlate setup;
  collette::CollisionWorld& world = setup.world;
  ToolProxy proxy(world, setup.tool_id, *setup.ball, {.enabled = true, .step_m = 0.002, .penetration_m = 0.0001}, true);
  proxy.watch(setup.plate_id);
  proxy.bind();
  // the handle 2 cm above the plate, then 3 cm into it for 40 steps, then 2 cm above again
  std::vector<double> heights;
  std::vector<std::int32_t> rows;
  ProxyState state{};
  for (int i = 0; i < 120; ++i) {
    Pose handle{};
    handle.position = {0.0, 0.0, i < 20 || i >= 60 ? 0.02 : -0.03};
    proxy.set_target(handle);
    world.step(1e-3 * i);
    if (const ProxyState* s = proxy.take()) state = *s;
    heights.push_back(state.world_from_proxy.position.z);
    rows.push_back(proxy.contact_rows(0));
  }
  const double resting = heights[59];  // 40 steps into the press: on the plate
  int on = 0, off = 0;
  for (std::size_t i = 1; i < heights.size(); ++i) {
    const bool resting_there = heights[i] - resting < 1e-4;
    EXPECT_EQ(rows[i] > 0, resting_there) << "step " << i << ": " << rows[i] << " rows in contact, the proxy "
                                          << 1e3 * (heights[i] - resting) << " mm above where it rests";
    (resting_there ? on : off) += 1;
  }
  EXPECT_GT(on, 30);
  EXPECT_GT(off, 60);
}

TEST(ToolProxy, SlidesAlongAFaceItIsPressedInto) {
  BallOverPlate setup;
  collette::CollisionWorld& world = setup.world;
  ToolProxy proxy(world, setup.tool_id, *setup.ball, {.enabled = true}, true);
  proxy.watch(setup.plate_id);
  proxy.bind();
  Pose handle;
  ProxyState state{};
  // press 5 mm into the face, then slide 2 cm along it at 2 cm/s
  for (int i = 0; i < 1500; ++i) {
    const double x = i < 500 ? 0.0 : std::min(0.02, 0.00002 * (i - 500));
    handle.position = {x - 0.01, 0.0, std::max(0.02 - 0.00005 * i, 0.0015)};
    proxy.set_target(handle);
    world.step(1e-3 * i);
    if (const ProxyState* s = proxy.take()) state = *s;
    EXPECT_GT(state.world_from_proxy.position.z, 0.0015 + 0.005 - setup.plate.max_gap - 0.0002) << "step " << i;
  }
  // it followed the handle 2 cm along the face, held on it (within the packing's grain, which
  // tilts the face the proxy rests on by a few degrees: issue 23's smoothing is not in yet)
  EXPECT_NEAR(state.world_from_proxy.position.x, handle.position.x, 5e-4);
  EXPECT_GT(state.active, 0);
  EXPECT_GT(proxy.stats().contact_updates, 500u);
  EXPECT_EQ(proxy.stats().unsolved, 0u);
}

// Slides a 1 cm ball (one sphere) 4 cm along the top face (z = 0) of a packed slab, the handle held
// `press_m` below the face's resting height; returns the RMS of the spring force's deviation from
// its mean over the slide, relative to the mean normal force, and the mean normal force.
struct Ripple {
  double relative = 0.0;
  double normal_n = 0.0;
};
Ripple slide_ripple(const Packed& slab, double smoothing_m, double press_m,
                    std::shared_ptr<const collette::MeshInside> surface = {}, double* lowest_m = nullptr) {
  const auto ball = std::make_shared<const collette::SphereTree>(
      *collette::build_sphere_tree(std::vector<Sphere>{{0.f, 0.f, 0.f, 0.005f}}));
  collette::CollisionWorld world({.rate_hz = 0.0, .contact_margin = 0.002});
  const auto slab_id = world.add_object({.tree = slab.tree, .is_static = true, .name = "slab"});
  const auto tool_id = world.add_object({.tree = ball, .has_initial_pose = false, .name = "ball"});
  EXPECT_TRUE(world.add_tool_watcher(*tool_id));
  ToolProxy proxy(world, *tool_id, *ball, {.enabled = true, .smoothing_m = smoothing_m}, true);
  proxy.watch(*slab_id, {.surface = std::move(surface)});
  proxy.bind();
  const double stiffness = 1500.0;
  Pose handle;
  ProxyState state{};
  std::vector<Vec3> forces;
  for (int i = 0; i < 4000; ++i) {
    // down onto the face at x = -2 cm, then along x at 2 cm/s
    const double x = i < 1000 ? -0.02 : std::min(0.02, -0.02 + 0.00002 * (i - 1000));
    handle.position = {x, 0.003, std::max(0.02 - 0.00005 * i, 0.005 - press_m)};
    proxy.set_target(handle);
    world.step(1e-3 * i);
    if (const ProxyState* s = proxy.take()) state = *s;
    if (i >= 1200 && i < 3000) {
      forces.push_back(stiffness * (proxy.slide(state, handle).position - handle.position));
      if (lowest_m != nullptr) *lowest_m = std::min(*lowest_m, state.world_from_proxy.position.z - 0.005);
    }
  }
  Vec3 mean{};
  for (const Vec3& f : forces) mean += f / static_cast<double>(forces.size());
  double sum = 0.0;
  for (const Vec3& f : forces) sum += squared_norm(f - mean);
  return {std::sqrt(sum / static_cast<double>(forces.size())) / mean.z, mean.z};
}

TEST(ToolProxy, SmoothingTakesPartOfTheGrainOutOfAPackedFace) {
  // the slab: 10 x 10 x 2 cm, 10,000 spheres of unbounded radius, the top face at z = 0
  const Packed slab = [] {
    collette::TriangleMesh m = box_mesh({0.1, 0.1, 0.02});
    for (Vec3& v : m.vertices) v.z -= 0.01;
    return pack(m, 10000);
  }();
  const Ripple raw = slide_ripple(slab, 0.0, 0.0015);
  const Ripple smooth = slide_ripple(slab, ToolProxyOptions{}.smoothing_m, 0.0015);
  std::printf("ripple on the union of spheres %.1f %%, smoothed over %.2f mm %.1f %% (normal force %.2f and %.2f N)\n",
              100 * raw.relative, ToolProxyOptions{}.smoothing_m * 1e3, 100 * smooth.relative, raw.normal_n,
              smooth.normal_n);
  // measured: 19.0 % and 10.8 %; issue 23 asks for 1 %, which the soft minimum does not reach
  EXPECT_LT(smooth.relative, 0.8 * raw.relative);
  EXPECT_GT(smooth.normal_n, 1.5);  // pressed 1.5 mm with 1500 N/m: about 2.2 N
}

// With the slab's mesh the proxy rests on the face itself, not on the packing's grain: the issue's
// bound is a ripple of 1 % of the normal force. The reference is the face (z = 0): the ball's lowest
// point stays within the allowed penetration of it, and the force is the spring's stiffness times
// how far the handle is below the ball resting on the face.
TEST(ToolProxy, RestsOnTheMeshSoAPackedFlatFaceDoesNotRipple) {
  for (const std::int64_t spheres : {2000, 10000, 50000}) {
    collette::TriangleMesh m = box_mesh({0.1, 0.1, 0.02});
    for (Vec3& v : m.vertices) v.z -= 0.01;
    const Packed slab = pack(m, spheres);
    auto surface = std::make_shared<const collette::MeshInside>(*collette::validate_mesh(m));
    double lowest = 1.0;
    const double press = 0.0015;
    const Ripple ripple = slide_ripple(slab, ToolProxyOptions{}.smoothing_m, press, surface, &lowest);
    std::printf("%lld spheres (surface gap %.2f mm): ripple on the mesh %.3f %% of %.3f N, lowest point %.4f mm\n",
                static_cast<long long>(spheres), slab.max_gap * 1e3, 100 * ripple.relative, ripple.normal_n,
                lowest * 1e3);
    EXPECT_LT(ripple.relative, 0.01) << spheres << " spheres";
    EXPECT_GT(lowest, -ToolProxyOptions{}.penetration_m - 1e-6) << spheres << " spheres";
    // the handle is press below where the ball rests (the face, less the allowed penetration)
    EXPECT_NEAR(ripple.normal_n, 1500.0 * (press - ToolProxyOptions{}.penetration_m), 0.02) << spheres << " spheres";
  }
}

// A packed slab given only as a .ist (the scene's `ist`, no mesh file) rests the proxy on the surface
// the .ist holds, as a meshed object does: the bound, a ripple of at most 1 % of the normal
// force, at 2,000, 10,000 and 50,000 spheres. The references: the same face given as a mesh (the same
// force) and the face itself (the ball's lowest point within the allowed penetration of z = 0, the
// force the spring's stiffness times how far the handle is below the ball resting there). The same
// packing in format 1 (no surface) rests on the spheres, smoothed: the grain the surface takes out.
TEST(ToolProxy, AnIstAloneRestsOnTheSurfaceItHolds) {
  const auto dir = testing::fresh_cache("ist-surface");
  collette::IstCache cache(dir / "cache");
  const auto object_of = [&](const std::filesystem::path& ist) -> CompiledShape {
    auto scene = parse_scene(testing::small_scene_json(), "small.json", testing::test_assets());
    EXPECT_TRUE(scene) << scene.error().message;
    scene->objects[0].shape = {.ist = ist};
    auto model = compile(*scene, cache);
    EXPECT_TRUE(model) << model.error().message;
    return model ? (*model)->objects[0] : CompiledShape{};
  };
  for (const std::int64_t spheres : {2000, 10000, 50000}) {
    collette::TriangleMesh m = box_mesh({0.1, 0.1, 0.02});
    for (Vec3& v : m.vertices) v.z -= 0.01;
    const auto mesh = collette::validate_mesh(m);
    ASSERT_TRUE(mesh) << mesh.error().message;
    auto built = collette::build_ist_asset(*mesh, 0, {.sphere_count = spheres});
    ASSERT_TRUE(built) << built.error().message;
    const auto with_surface = dir / fmt::format("slab{}.ist", spheres);
    ASSERT_TRUE(collette::save_ist(with_surface, built->asset));
    built->asset.surface.reset();
    const auto format1 = dir / fmt::format("slab{}_format1.ist", spheres);
    ASSERT_TRUE(collette::save_ist(format1, built->asset));

    const CompiledShape slab = object_of(with_surface);
    ASSERT_NE(slab.surface, nullptr) << "the .ist's surface";
    EXPECT_EQ(slab.surface_gap_m, built->packing.max_gap);
    const Packed packed{slab.tree, slab.surface_gap_m};
    const double press = 0.0015, smoothing = ToolProxyOptions{}.smoothing_m;
    double lowest = 1.0;
    const Ripple on_ist = slide_ripple(packed, smoothing, press, slab.surface, &lowest);
    const Ripple on_mesh = slide_ripple(packed, smoothing, press, std::make_shared<const collette::MeshInside>(*mesh));
    const CompiledShape old = object_of(format1);
    EXPECT_EQ(old.surface, nullptr) << "a format 1 .ist has none";
    const Ripple on_grain = slide_ripple(Packed{old.tree, old.surface_gap_m}, smoothing, press);
    std::printf("%lld spheres, a .ist alone: ripple %.3f %% of %.3f N with its surface (the mesh: %.3f %% of %.3f N), "
                "%.1f %% of %.3f N without (format 1); lowest point %.4f mm\n",
                static_cast<long long>(spheres), 100 * on_ist.relative, on_ist.normal_n, 100 * on_mesh.relative,
                on_mesh.normal_n, 100 * on_grain.relative, on_grain.normal_n, lowest * 1e3);
    EXPECT_LT(on_ist.relative, 0.01) << spheres << " spheres";
    EXPECT_NEAR(on_ist.normal_n, on_mesh.normal_n, 1e-3) << spheres << " spheres";
    EXPECT_GT(lowest, -ToolProxyOptions{}.penetration_m - 1e-6) << spheres << " spheres";
    EXPECT_NEAR(on_ist.normal_n, 1500.0 * (press - ToolProxyOptions{}.penetration_m), 0.02) << spheres << " spheres";
  }
  std::filesystem::remove_all(dir);
}

// Force continuity over an edge: a ball pressed 1.5 mm into a packed slab's top face and drawn at
// 2 cm/s off its edge rolls over it on the proxy; the force's change per tick stays within what the
// spring does when the handle moves, K v T (times two: the proxy moves as far), at the edge too.
TEST(ToolProxy, TheForceChangesByAtMostKvTPerTickOverAnEdge) {
  collette::TriangleMesh m = box_mesh({0.1, 0.1, 0.02});
  for (Vec3& v : m.vertices) v.z -= 0.01;  // top face at z = 0, the edge at x = 0.05
  const Packed slab = pack(m, 10000);
  const auto ball = std::make_shared<const collette::SphereTree>(
      *collette::build_sphere_tree(std::vector<Sphere>{{0.f, 0.f, 0.f, 0.005f}}));
  collette::CollisionWorld world({.rate_hz = 0.0, .contact_margin = 0.002});
  const auto slab_id = world.add_object({.tree = slab.tree, .is_static = true, .name = "slab"});
  const auto tool_id = world.add_object({.tree = ball, .has_initial_pose = false, .name = "ball"});
  ASSERT_TRUE(world.add_tool_watcher(*tool_id));
  ToolProxy proxy(world, *tool_id, *ball, {.enabled = true}, true);
  proxy.watch(*slab_id, {.surface = std::make_shared<const collette::MeshInside>(*collette::validate_mesh(m))});
  proxy.bind();
  const double stiffness = 1500.0, speed = 0.02, period = 1e-3;
  Pose handle;
  ProxyState state{};
  Vec3 last{};
  double largest_step = 0.0, largest_force = 0.0, lowest = 1.0;
  for (int i = 0; i < 4000; ++i) {
    // down onto the face at x = 4 cm, then along x at 2 cm/s to 2 cm past the edge
    const double x = i < 1000 ? 0.04 : 0.04 + speed * period * (i - 1000);
    handle.position = {x, 0.0, std::max(0.02 - 0.00005 * i, 0.0035)};
    proxy.set_target(handle);
    world.step(period * i);
    if (const ProxyState* s = proxy.take()) state = *s;
    const Vec3 force = stiffness * (proxy.slide(state, handle).position - handle.position);
    if (i > 1000) largest_step = std::max(largest_step, norm(force - last));
    largest_force = std::max(largest_force, norm(force));
    lowest = std::min(lowest, state.world_from_proxy.position.z - 0.005);
    last = force;
  }
  std::printf("over the edge: largest force %.3f N, largest step per tick %.4f N (K v T = %.4f N)\n", largest_force,
              largest_step, stiffness * speed * period);
  EXPECT_GT(largest_force, 2.0);  // it was pressed
  EXPECT_LE(largest_step, 2.0 * stiffness * speed * period);
  EXPECT_GT(proxy.pose().position.z, -0.0055);  // and went over the edge, not through the slab
}

// An L-shaped block (one closed mesh, its cross-section in x-z extruded 6 cm along y): a floor
// face at z = 0 for x in [0.02, 0.06] and a wall face at x = 0.02 for z in [0, 0.04] meet in a
// concave crease along y at (0.02, 0).
collette::TriangleMesh l_block_mesh() {
  collette::TriangleMesh m;
  m.source_name = "l_block";
  const double section[6][2] = {{0.0, -0.02}, {0.06, -0.02}, {0.06, 0.0}, {0.02, 0.0}, {0.02, 0.04}, {0.0, 0.04}};
  for (const double y : {-0.03, 0.03})
    for (const auto& xz : section) m.vertices.push_back({xz[0], y, xz[1]});
  // the caps: a fan from the corner (0, -0.02), which sees every other corner of the L
  for (std::int32_t i = 1; i + 1 < 6; ++i) {
    m.triangles.push_back({0, i, i + 1});          // y = -0.03, facing -y
    m.triangles.push_back({6, 6 + i + 1, 6 + i});  // y = +0.03, facing +y
  }
  for (std::int32_t i = 0; i < 6; ++i) {  // the sides, around the section counter-clockwise seen from -y
    const std::int32_t j = (i + 1) % 6;
    m.triangles.push_back({i, 6 + j, j});
    m.triangles.push_back({i, 6 + i, 6 + j});
  }
  return m;
}

// Force continuity in a concave crease of one mesh: a ball pressed into the L's inner corner along
// the bisector, and then drawn out of it along the floor, is held by both faces at once. The
// reference is the geometry: resting in the corner, the ball's centre is its radius (less the
// allowed penetration) from each face, and the force is the spring's stiffness times the handle's
// distance from there, so it changes by K v T a tick while the handle moves at v. Before each tool
// sphere had a row for every face near it, the crease gave the ball one face at a time, and which
// one flipped from tick to tick.
TEST(ToolProxy, AConcaveCreaseHoldsTheToolOnBothFacesAtOnce) {
  const collette::TriangleMesh m = l_block_mesh();
  const auto valid = collette::validate_mesh(m);
  ASSERT_TRUE(valid) << valid.error().message;
  ASSERT_FALSE(valid->report.winding_flipped) << "the L is wound outward";
  const Packed block = pack(m, 10000);
  const double radius = 0.005;
  const auto ball = std::make_shared<const collette::SphereTree>(
      *collette::build_sphere_tree(std::vector<Sphere>{{0.f, 0.f, 0.f, static_cast<float>(radius)}}));
  collette::CollisionWorld world({.rate_hz = 0.0, .contact_margin = 0.002});
  const auto block_id = world.add_object({.tree = block.tree, .is_static = true, .name = "l_block"});
  const auto tool_id = world.add_object({.tree = ball, .has_initial_pose = false, .name = "ball"});
  ASSERT_TRUE(world.add_tool_watcher(*tool_id));
  ToolProxy proxy(world, *tool_id, *ball, {.enabled = true}, true);
  proxy.watch(*block_id, {.surface = std::make_shared<const collette::MeshInside>(*valid)});
  proxy.bind();
  const double stiffness = 1500.0, speed = 0.01, period = 1e-3, allowed = ToolProxyOptions{}.penetration_m;
  const Vec3 corner{0.02, 0.0, 0.0}, bisector = normalized(Vec3{1.0, 0.0, 1.0});
  const Vec3 rest = corner + (radius - allowed) * Vec3{1.0, 0.0, 1.0};  // touching both faces
  Pose handle;
  ProxyState state{};
  Vec3 last{};
  double largest_step = 0.0, largest_force = 0.0, nearest_face = 1.0, farthest_from_rest = 0.0;
  const int ticks = 5000;
  for (int i = 0; i < ticks; ++i) {
    // from 2 cm out along the bisector in, at 1 cm/s, to 2 mm past where the ball rests; held for
    // half a second; then along the floor, away from the wall, at 1 cm/s
    const double in = std::min(speed * period * i, 0.02 + 0.002);
    const double out = std::max(0.0, speed * period * (i - 2700));
    handle.position = rest + (0.02 - in) * bisector + Vec3{out, 0.0, 0.0};
    proxy.set_target(handle);
    world.step(period * i);
    if (const ProxyState* s = proxy.take()) state = *s;
    const Vec3 force = stiffness * (proxy.slide(state, handle).position - handle.position);
    if (i > 0) largest_step = std::max(largest_step, norm(force - last));
    largest_force = std::max(largest_force, norm(force));
    const Vec3 c = state.world_from_proxy.position;
    nearest_face = std::min(nearest_face, std::max(c.x - corner.x, c.z - corner.z) - radius);
    if (i >= 2300 && i < 2700) farthest_from_rest = std::max(farthest_from_rest, norm(c - rest));
    last = force;
  }
  std::printf("in a concave crease: largest force %.3f N, largest step per tick %.4f N (K v T = %.4f N), "
              "resting %.4f mm from both faces' rest, nearest a face %.4f mm\n",
              largest_force, largest_step, stiffness * speed * period, farthest_from_rest * 1e3, nearest_face * 1e3);
  EXPECT_GT(largest_force, 2.5);  // pressed 2 mm past the rest: 3 N along the bisector
  EXPECT_LE(largest_step, 2.0 * stiffness * speed * period);
  EXPECT_LT(farthest_from_rest, 0.1e-3);
  EXPECT_GT(nearest_face, -allowed - 1e-6);
}

// A square peg (10 x 10 x 40 mm, packed) lowered, tilted 3 deg and 0.5 mm off centre, into a
// 12 mm square hole 4 cm deep (four packed walls and a floor, each with its mesh): the 6-DOF proxy
// slides and turns it down to the floor without snagging on the walls' packing, turning it by at
// most a small angle per step. The reference is the geometry: the peg's lowest sphere ends within
// the peg's own packing gap and the allowed penetration of the floor, and no peg sphere's centre
// ever comes nearer a wall's face than its radius less the penetration.
TEST(ToolProxy, APegSlidesIntoAHoleWithoutSnagging) {
  struct Block {
    Vec3 size, centre;
  };
  const double half = 0.006;  // the hole's half width
  const std::vector<Block> blocks{{{0.02, 0.052, 0.04}, {-half - 0.01, 0, -0.02}},
                                  {{0.02, 0.052, 0.04}, {half + 0.01, 0, -0.02}},
                                  {{0.012, 0.02, 0.04}, {0, -half - 0.01, -0.02}},
                                  {{0.012, 0.02, 0.04}, {0, half + 0.01, -0.02}},
                                  {{0.052, 0.052, 0.01}, {0, 0, -0.045}}};
  collette::CollisionWorld world({.rate_hz = 0.0, .contact_margin = 0.002});
  std::vector<collette::ObjectId> ids;
  std::vector<std::shared_ptr<const collette::MeshInside>> surfaces;
  for (const Block& b : blocks) {
    collette::TriangleMesh m = box_mesh(b.size);
    for (Vec3& v : m.vertices) v += b.centre;
    const Packed packed = pack(m, 3000);
    const auto id = world.add_object({.tree = packed.tree, .is_static = true, .name = "wall"});
    ASSERT_TRUE(id);
    ids.push_back(*id);
    surfaces.push_back(std::make_shared<const collette::MeshInside>(*collette::validate_mesh(m)));
  }
  const Packed peg = pack(box_mesh({0.01, 0.01, 0.04}), 3000);
  const auto tool_id = world.add_object({.tree = peg.tree, .has_initial_pose = false, .name = "peg"});
  ASSERT_TRUE(world.add_tool_watcher(*tool_id));
  ToolProxy proxy(world, *tool_id, *peg.tree, {.enabled = true}, true);
  for (std::size_t i = 0; i < ids.size(); ++i) proxy.watch(ids[i], {.surface = surfaces[i]});
  proxy.bind();
  Pose handle;
  handle.rotation = quat_from_axis_angle({0, 1, 0}, 3.0 * kPi / 180.0);
  Quat previous = handle.rotation;
  double largest_turn = 0.0, nearest_wall = 1.0;
  for (int i = 0; i < 4000; ++i) {
    // from 1 cm above the hole down at 2 cm/s, the handle aiming 1 cm below the floor
    handle.position = {0.0005, 0.0, std::max(0.04 - 0.00002 * i, -0.03)};
    proxy.set_target(handle);
    world.step(1e-3 * i);
    const Pose& now = proxy.pose();
    largest_turn = std::max(largest_turn, std::abs(forcecomp::rotation_vector(now.rotation * conjugate(previous)).y));
    previous = now.rotation;
    if (i % 50 == 0)
      for (const Sphere& s : peg.tree->leaves()) {
        const Vec3 c = transform_point(now, centre_of(s));
        if (c.z < 0.0 && c.z > -0.04)  // beside the walls: their faces are x, y = +-half
          nearest_wall = std::min(nearest_wall, half - std::max(std::abs(c.x), std::abs(c.y)) - static_cast<double>(s.radius));
      }
  }
  double lowest = 1.0;
  for (const Sphere& s : peg.tree->leaves())
    lowest = std::min(lowest, transform_point(proxy.pose(), centre_of(s)).z - static_cast<double>(s.radius));
  std::printf("peg in a hole: lowest point %.2f mm above the floor (peg's packing gap %.2f mm), nearest a wall %.3f mm, "
              "largest turn per step %.3f deg, %llu unsolved\n",
              (lowest + 0.04) * 1e3, peg.max_gap * 1e3, nearest_wall * 1e3, largest_turn * 180.0 / kPi,
              static_cast<unsigned long long>(proxy.stats().unsolved));
  EXPECT_LT(lowest + 0.04, peg.max_gap + 0.0005) << "snagged above the floor";
  EXPECT_GT(lowest + 0.04, -ToolProxyOptions{}.penetration_m - 1e-5);
  EXPECT_GT(nearest_wall, -ToolProxyOptions{}.penetration_m - 1e-5);
  EXPECT_LT(largest_turn, 0.5 * kPi / 180.0);
}

// Friction as a cone on the proxy: a ball pressed into a packed face with about 2 N and pulled
// sideways sticks until the sideways force is mu_s times the normal force, then slides at mu_d.
// The reference is Coulomb's law on the spring force the device would feel, at every tick of the
// slide: a cone tilted by the packing's grain from step to step breaks a slide into stick and slip
// (a sawtooth between 0 and mu_s N whose ticks in slip alone still read mu_d).
class Friction : public ::testing::TestWithParam<bool> {};  // on the mesh, or on the spheres' union

TEST_P(Friction, SticksUntilMuStaticThenSlidesAtMuDynamic) {
  collette::TriangleMesh m = box_mesh({0.1, 0.1, 0.02});
  for (Vec3& v : m.vertices) v.z -= 0.01;
  const Packed slab = pack(m, 10000);
  std::shared_ptr<const collette::MeshInside> surface;
  if (GetParam()) surface = std::make_shared<const collette::MeshInside>(*collette::validate_mesh(m));
  const auto ball = std::make_shared<const collette::SphereTree>(
      *collette::build_sphere_tree(std::vector<Sphere>{{0.f, 0.f, 0.f, 0.005f}}));
  collette::CollisionWorld world({.rate_hz = 0.0, .contact_margin = 0.002});
  const auto slab_id = world.add_object({.tree = slab.tree, .is_static = true, .name = "slab"});
  const auto tool_id = world.add_object({.tree = ball, .has_initial_pose = false, .name = "ball"});
  ASSERT_TRUE(world.add_tool_watcher(*tool_id));
  ToolProxy proxy(world, *tool_id, *ball, {.enabled = true}, true);
  proxy.watch(*slab_id, {.friction_static = 0.6, .friction_dynamic = 0.4, .surface = surface});
  proxy.bind();
  const double stiffness = 1500.0;
  Pose handle;
  ProxyState state{};
  double peak_ratio = 0.0;           // the largest sideways / normal force before the proxy first slid
  double break_ratio = 0.0;          // that ratio at the tick before it first slid
  bool slid = false;
  std::vector<double> sliding_ratios;  // every tick of the slide (the handle's second half)
  double last_ratio = 0.0;
  for (int i = 0; i < 4000; ++i) {
    // down onto the face, then the handle moves sideways at 1 cm/s
    const double x = i < 1000 ? -0.01 : -0.01 + 0.00001 * (i - 1000);
    handle.position = {x, 0.0, std::max(0.02 - 0.00005 * i, 0.005 - 0.0015)};
    proxy.set_target(handle);
    world.step(1e-3 * i);
    if (const ProxyState* st = proxy.take()) state = *st;
    if (i < 1000) continue;  // pressed and settled (the handle stops at 3.5 mm from tick 330)
    const Vec3 f = stiffness * (proxy.slide(state, handle).position - handle.position);
    const double ratio = std::hypot(f.x, f.y) / f.z;
    if (!slid && state.sliding) break_ratio = peak_ratio > 0.0 ? last_ratio : ratio;
    slid |= state.sliding;
    if (!slid) peak_ratio = std::max(peak_ratio, ratio);
    last_ratio = ratio;
    if (i > 2000) sliding_ratios.push_back(ratio);
  }
  ASSERT_TRUE(slid) << "the handle moved 3 cm sideways: the proxy must have broken away";
  // the breakaway: the pull reaches mu_s times the normal force about the contact's normal: the
  // mesh's (measured 0.555), or the smoothed union's, which the packing's grain tilts by a few
  // degrees from the face's (measured 0.72, 20 % high)
  const double breakaway_tolerance = GetParam() ? 0.1 : 0.15;
  EXPECT_NEAR(break_ratio, 0.6, breakaway_tolerance);
  EXPECT_LT(peak_ratio, 0.6 + breakaway_tolerance);
  ASSERT_EQ(sliding_ratios.size(), 1999u);
  std::sort(sliding_ratios.begin(), sliding_ratios.end());
  const double median = sliding_ratios[sliding_ratios.size() / 2];
  const double low = sliding_ratios[sliding_ratios.size() / 20];  // the 5th percentile
  std::printf("friction on the proxy (%s): breakaway at %.3f (mu_s 0.6; largest before it %.3f), sliding median %.3f, "
              "5th percentile %.3f (mu_d 0.4)\n",
              GetParam() ? "mesh" : "spheres", break_ratio, peak_ratio, median, low);
  EXPECT_NEAR(median, 0.4, 0.04);
  EXPECT_GT(low, 0.3) << "the slide sticks and slips";
}
INSTANTIATE_TEST_SUITE_P(OnTheMeshAndOnTheSpheres, Friction, ::testing::Values(true, false));

// The whole session (scenes/thin_wall.json): a simulated hand pulls the 1 cm ball 3 cm through a
// 3 mm plate tilted 20 degrees with up to 8 N. Through the proxy the ball stays on its side and the
// hand is held with the hand's whole pull; the penalty path, run on the same scene, lets it through
// (what the test would see if the proxy did not hold).
struct ThinWallRun {
  double closest_m = 1e9;  // the ball's centre nearest the plate's mid-plane, along its normal [m]
  double handle_closest_m = 1e9;
  double held_force_n = 0.0;  // the force along the normal from 2.5 to 2.9 s, smallest [N]
};

ThinWallRun run_thin_wall(bool proxy, const std::filesystem::path& cache) {
  auto scene = load_scene(testing::test_assets().parent_path() / "scenes" / "thin_wall.json");
  EXPECT_TRUE(scene) << scene.error().message;
  scene->force.proxy.enabled = proxy;
  SessionOptions options;
  options.cache_dir = cache;
  auto session = HapticSession::create(*scene, options);
  EXPECT_TRUE(session) << session.error().message;
  const Vec3 normal = rotate(scene->objects.front().pose.rotation, Vec3{0, 0, 1});
  ThinWallRun run;
  run.held_force_n = 1e9;
  auto seen = (*session)->on_haptic_tick().connect([&](const SessionState& s) {
    run.closest_m = std::min(run.closest_m, dot(s.tool_position_world, normal));
    run.handle_closest_m = std::min(run.handle_closest_m, dot(s.handle_position_world, normal));
    if (s.time_s > 2.5 && s.time_s < 2.9) run.held_force_n = std::min(run.held_force_n, dot(s.force_world, normal));
  });
  EXPECT_TRUE((*session)->run_stepped(3.0, 1).has_value());
  return run;
}

TEST(ToolProxy, TheThinWallSceneHoldsTheHandWhereThePenaltyPathLetsItThrough) {
  const std::filesystem::path cache = testing::fresh_cache("thin_wall");
  const ThinWallRun held = run_thin_wall(true, cache);
  // the ball (radius 5 mm) on the plate (half thickness 1.5 mm): its centre 6.5 mm from the
  // mid-plane, less the packing's surface gap (under 1 mm at 10,000 spheres)
  EXPECT_GT(held.closest_m, 0.0055);
  EXPECT_LT(held.handle_closest_m, 0.004);  // the hand did push into the plate
  EXPECT_GT(held.held_force_n, 6.0);        // and is held with its pull (up to the 8 N limit)
  const ThinWallRun through = run_thin_wall(false, cache);
  EXPECT_LT(through.closest_m, -0.02);  // the penalty path: the ball ends behind the plate
  std::filesystem::remove_all(cache);
}

using testing::energy_into_hand;
using testing::hand_device_damping;

// Passivity with a hand that reacts (scenes/bunny_hand_press.json: a sim-hand presses the stylus
// 5 cm into the bunny and pulls it out, twice): through the proxy, whose spring is clamped to the
// passive bound for the device's damping at the haptic period (Colgate: a sampled spring K is
// passive with the device's damping b when b > K T / 2), no energy reaches the hand through the
// handle over the closed presses, at 1 and 4 kHz. The reference is the energy balance of the hand
// device (the sim-hand integrates the motors' force and its mechanism's damping); the motors alone
// may give back what the zero-order hold gains, at most K T / 2 times the squared speed's integral.
TEST(ToolProxy, RepeatedPressesPutNoEnergyIntoAReactingHand) {
  auto scene = load_scene(testing::test_assets().parent_path() / "scenes" / "bunny_hand_press.json");
  ASSERT_TRUE(scene) << scene.error().message;
  // a hard material, so that the spring rendered is the coupling's clamp (the bound under test), not
  // the material's own, softer spring (2 pi r k: 0.4 kN/m for this stylus at the scene's k)
  scene->tool().force.stiffness = 1e6;
  const double b = hand_device_damping(*scene);
  const std::filesystem::path cache = testing::fresh_cache("hand_press_proxy");
  for (const double hz : {1000.0, 4000.0}) {
    SessionOptions options;
    options.cache_dir = cache;
    options.proxy = true;
    options.haptic_hz = hz;
    auto session = HapticSession::create(*scene, options);
    ASSERT_TRUE(session) << session.error().message;
    ASSERT_TRUE((*session)->run_stepped(scene->seconds, static_cast<int>(hz / 1000.0)).has_value());
    const SessionReport& r = (*session)->report();
    std::printf("%.0f Hz: motors' work %+.3f mJ, the device's damping in contact %.3f mJ, into the hand %+.3f mJ\n", hz,
                r.work_on_hand_j * 1e3, b * r.contact_squared_speed_integral * 1e3, energy_into_hand(r, b) * 1e3);
    EXPECT_GT(r.proxy_stats.contact_updates, 200u) << hz << " Hz: the presses reach the bunny";
    EXPECT_GT(r.force_max_n, 3.0) << hz << " Hz: and are pushed back";
    EXPECT_LE(energy_into_hand(r, b), 0.0) << hz << " Hz";
    // and the motors' gain is within the zero-order hold's, K T / 2 (the clamp: 0.9 b) per squared speed
    EXPECT_LE(r.work_on_hand_j, 0.9 * b * r.contact_squared_speed_integral) << hz << " Hz";
  }
  // the counter-example: told ten times the device's real damping, the spring is 9x too stiff and
  // the same presses put energy into the hand (measured +0.79 J of the motors' work), which the
  // measure catches whatever the mechanism dissipates
  auto too_stiff = load_scene(testing::test_assets().parent_path() / "scenes" / "bunny_hand_press_too_stiff.json");
  ASSERT_TRUE(too_stiff) << too_stiff.error().message;
  too_stiff->tool().force.stiffness = 1e6;
  SessionOptions options;
  options.cache_dir = cache;
  options.proxy = true;
  auto session = HapticSession::create(*too_stiff, options);
  ASSERT_TRUE(session) << session.error().message;
  ASSERT_TRUE((*session)->run_stepped(too_stiff->seconds, 1).has_value());
  const SessionReport& r = (*session)->report();
  std::printf("too stiff: motors' work %+.3f mJ, into the hand %+.3f mJ\n", r.work_on_hand_j * 1e3,
              energy_into_hand(r, hand_device_damping(*too_stiff)) * 1e3);
  EXPECT_GT(energy_into_hand(r, hand_device_damping(*too_stiff)), 0.01);
  std::filesystem::remove_all(cache);
}

// A stalled collision thread (here: stepped only every 100 ms) leaves the proxy's data stale: the
// safety chain's watchdog takes the spring to zero within its ramp after the data's age passes its
// bound, as it does the penalty path's, and no force is sent on data older than that plus the ramp.
TEST(ToolProxy, AStalledCollisionThreadFadesTheSpringToZero) {
  auto scene = load_scene(testing::test_assets().parent_path() / "scenes" / "bunny_hand_press.json");
  ASSERT_TRUE(scene) << scene.error().message;
  const double max_age = scene->force.safety.watchdog.max_age_s;
  const double ramp = scene->force.safety.watchdog.ramp_s;
  ASSERT_LT(max_age + ramp, 0.09);  // a step every 100 ms leaves stale ticks in every period
  scene->force.proxy.step_m = 0.01;  // so that the proxy, a step per 100 ms, keeps up with the hand
  const std::filesystem::path cache = testing::fresh_cache("proxy_stall");
  SessionOptions options;
  options.cache_dir = cache;
  options.proxy = true;
  auto session = HapticSession::create(*scene, options);
  ASSERT_TRUE(session) << session.error().message;
  std::stringstream trace;
  ASSERT_TRUE((*session)->run_stepped(scene->seconds, 100, &trace).has_value());
  EXPECT_GT((*session)->report().proxy_stats.contact_updates, 5u);
  std::string line;
  std::getline(trace, line);  // header: tick_time_s, ..., fx, fy, fz at columns 23-25
  int pushed = 0, late = 0, late_with_force = 0;
  for (int tick = 0; std::getline(trace, line); ++tick) {
    std::vector<double> cells;
    std::stringstream row(line);
    for (std::string cell; std::getline(row, cell, ',');) cells.push_back(std::strtod(cell.c_str(), nullptr));
    ASSERT_GE(cells.size(), 26u);
    const double force = std::hypot(cells[23], cells[24], cells[25]);
    const double since_step = (tick % 100) * 1e-3;  // the collision step runs before tick 0, 100, ...
    if (force > 0.5) ++pushed;
    if (since_step > max_age + ramp + 2e-3) {
      ++late;
      if (force > 0.0) ++late_with_force;
    }
  }
  EXPECT_GT(pushed, 20) << "the presses are pushed back while the data is fresh";
  EXPECT_GT(late, 1000);
  EXPECT_EQ(late_with_force, 0) << "force sent on data older than the watchdog's age and ramp";
  std::filesystem::remove_all(cache);
}

// The spring a ball pressed straight down into scenes/materials_block.json's `object` feels [N/m]:
// the slope of the force against the handle's depth over the force's middle range (0.3 to 2.5 N),
// fitted over the descent's ticks, rendered through the proxy or the penalty path.
double pressed_spring_n_m(const std::string& object, bool proxy, const std::filesystem::path& cache) {
  auto scene = load_scene(testing::test_assets().parent_path() / "scenes" / "materials_block.json");
  EXPECT_TRUE(scene) << scene.error().message;
  if (!scene) return 0.0;
  std::erase_if(scene->objects, [&](const SceneObject& o) { return o.name != object; });
  scene->watch = {object};
  // a device damped enough that the proxy's spring may reach the stiffer material's (Colgate's bound
  // 2 b / T is 10 kN/m): the coupling's clamp, 1.5 kN/m by default, would cap it below the penalty's
  scene->force.coupling.stiffness = 5000.0;
  scene->force.coupling.device_damping = 5.0;
  const double x = scene->objects[0].pose.position.x;
  scene->tool().device.config.set("start", Vec3{x, 0.0, 0.012}).set("end", Vec3{x, 0.0, -0.004});
  SessionOptions options;
  options.cache_dir = cache;
  options.proxy = proxy;
  auto session = HapticSession::create(*scene, options);
  EXPECT_TRUE(session) << session.error().message;
  if (!session) return 0.0;
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  auto seen = (*session)->on_haptic_tick().connect([&](const SessionState& s) {
    const double depth = -s.handle_position_world.z, force = s.force_world.z;
    if (s.time_s > 1.9 || force < 0.3 || force > 2.5) return;  // the descent, the force's middle range
    n += 1, sx += depth, sy += force, sxx += depth * depth, sxy += depth * force;
  });
  EXPECT_TRUE((*session)->run_stepped(2.0, 1).has_value());
  EXPECT_GT(n, 50) << object << (proxy ? ", proxy" : ", penalty") << ": the press reaches the force's middle range";
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

// A material's stiffness is felt through the proxy as through the penalty path: the proxy renders
// the gradient law's spring of a round tip, and the reference is the penalty path's own force
// against depth, summed from the sphere pairs' overlaps in the same run (the default material and
// a stiffer one, which must also feel stiffer), within 20 %.
TEST(ToolProxy, AMaterialFeelsAsStiffThroughTheProxyAsThroughThePenaltyPath) {
  const std::filesystem::path cache = testing::fresh_cache("proxy_material");
  double proxy_springs[2] = {};
  int i = 0;
  for (const char* object : {"plain", "stiff"}) {
    const double penalty = pressed_spring_n_m(object, false, cache);
    const double proxy = pressed_spring_n_m(object, true, cache);
    std::printf("%s: penalty %.0f N/m, proxy %.0f N/m\n", object, penalty, proxy);
    EXPECT_NEAR(proxy / penalty, 1.0, 0.2) << object;
    proxy_springs[i++] = proxy;
  }
  EXPECT_GT(proxy_springs[1], 1.2 * proxy_springs[0]) << "the stiffer material feels stiffer";
  std::filesystem::remove_all(cache);
}

// The default scene's bunny and stylus through the proxy, run stepped at 1 kHz with the raster's
// device swapped for `line` when it is given (start, end, seconds each way) and a hard material, so
// that the spring rendered is the coupling's clamp, 1.5 kN/m; returns the session's report.
SessionReport run_bunny_sweep(const std::filesystem::path& cache, double seconds, const Vec3* line = nullptr,
                              double line_s = 0.0) {
  auto scene = load_scene(testing::test_assets().parent_path() / "scenes" / "bunny_sweep.json");
  EXPECT_TRUE(scene) << scene.error().message;
  if (!scene) return {};
  scene->tool().force.stiffness = 1e6;
  if (line != nullptr) {
    scene->tool().device.driver = "sim-line";
    scene->tool().device.config = {};
    scene->tool().device.config.set("start", line[0]).set("end", line[1]).set("duration_s", line_s);
    scene->tool().device.config.set("dof_actuated", 6.0).set("max_force_n", 8.0);
  }
  SessionOptions options;
  options.cache_dir = cache;
  options.proxy = true;
  auto session = HapticSession::create(*scene, options);
  EXPECT_TRUE(session) << session.error().message;
  if (!session) return {};
  EXPECT_TRUE((*session)->run_stepped(seconds, 1).has_value());
  return (*session)->report();
}

// Force continuity through the proxy as the device gets it (the contact force before the limit
// chain), K the spring rendered, v the handle's speed (5 cm/s), T the haptic period (1 ms).
// Pressed 5 mm straight down onto the bunny's back and pulled out (landing, release), the force
// changes by at most 2 K v T a tick. Dragged by the default raster through the bunny's head, the
// stylus is held on an ear while the handle goes on up to 4 cm, and slips off the ear's end with the
// spring stretched 14 mm: the force then falls as fast as the proxy may move towards the handle, a
// slide's reach a tick (step_m / sqrt 2, in the solver's metric), and no faster: K (reach + v T).
// Before the rendered proxy's move was capped (ToolProxy::towards) it fell by half as much again
// in the tick that freed the proxy: the step's move and a whole free slide on top of the last
// tick's slide, which a row held (2.5 N for a bound of 2.2 N; 0.83 N on the scene's own material).
TEST(ToolProxy, TheForceStepsByKvTAtLandingAndReleaseAndNoFasterThanTheProxyMovesOffAnEdge) {
  const std::filesystem::path cache = testing::fresh_cache("proxy_continuity");
  const double spring = forcecomp::VirtualCoupling().stiffness(), speed = 0.05, period = 1e-3;
  const double kvt = spring * speed * period;
  const Vec3 press[2] = {{0.01, 0.0, 0.08}, {0.01, 0.0, 0.058}};  // the back's top is at 6.3 cm
  const SessionReport pressed = run_bunny_sweep(cache, 1.76, press, norm(press[1] - press[0]) / speed);
  std::printf("landing and release: largest step %.4f N (K v T %.4f N), largest force %.3f N\n",
              pressed.force_max_raw_step_n, kvt, pressed.force_max_n);
  EXPECT_GT(pressed.force_max_n, 3.0);  // pressed (about 3 mm under the proxy at 1.5 N/mm)
  EXPECT_LE(pressed.force_max_raw_step_n, 2.0 * kvt);

  const SessionReport swept = run_bunny_sweep(cache, 8.1);
  const double reach = ToolProxyOptions{}.step_m / std::sqrt(2.0);
  std::printf("slipping off the ear: largest step %.3f N (K (reach + v T) %.3f N)\n", swept.force_max_raw_step_n,
              spring * (reach + speed * period));
  EXPECT_GT(swept.force_max_raw_step_n, 10.0 * kvt);  // it slipped off
  EXPECT_LE(swept.force_max_raw_step_n, spring * (reach + speed * period));
  std::filesystem::remove_all(cache);
}

}  // namespace
}  // namespace uh::controllers
