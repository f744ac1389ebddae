// Torques through the 6-DOF proxy, rendered by the force controller as a device would get them:
// the torque spring from the handle's orientation to the proxy's (K R^2 by default, the solver's
// metric, within the rotational passivity bound). The references are geometric and physical: the
// moment r x F of the force felt about the tool's centre for the contact point the geometry
// predicts, a peg's depth and speed in a hole against the hand's, the overlap of every pair of
// spheres, the spring's K w T per tick, and the energy balance of a hand that turns against the
// contact.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "proxy_test_support.hpp"
#include "scene_test_support.hpp"
#include "uh/collette/collision_world.hpp"
#include "uh/collette/mesh_inside.hpp"
#include "uh/controllers/force_controller.hpp"
#include "uh/controllers/haptic_session.hpp"
#include "uh/controllers/tool_proxy.hpp"
#include "uh/forcecomp/virtual_coupling.hpp"

namespace uh::controllers {
namespace {

using testing::box_mesh;
using testing::deepest_overlap;
using testing::pack;
using testing::Packed;

// A packed tool, static packed objects with their mesh surfaces, the tool's proxy and the force
// controller that renders the spring to it, stepped by hand: a collision step, then haptic ticks.
class ProxyRig {
 public:
  explicit ProxyRig(const Packed& tool, double haptic_hz = 1000.0, const ForceControllerOptions& given = {})
      : world_(std::make_unique<collette::CollisionWorld>(
            collette::CollisionWorldOptions{.rate_hz = 0.0, .contact_margin = given.proxy.step_m})),
        tool_tree_(tool.tree),
        options_(given) {
    options_.coupling.period_s = 1.0 / haptic_hz;
    tool_ = *world_->add_object({.tree = tool.tree, .has_initial_pose = false, .name = "tool"});
    EXPECT_TRUE(world_->add_tool_watcher(tool_));
    proxy_ = std::make_unique<ToolProxy>(*world_, tool_, *tool.tree, options_.proxy, true);
    controller_ = std::make_unique<ForceController>(
        tool_, forcecomp::ForceComponent({.mode = forcecomp::ForceMode::k6Dof}), WorkspaceMapping{},
        options_);
    controller_->render_through(proxy_.get());
  }

  void add_object(const collette::TriangleMesh& mesh, const Packed& packed) {
    const auto id = world_->add_object({.tree = packed.tree, .is_static = true, .name = "object"});
    ASSERT_TRUE(id);
    proxy_->watch(*id,
                  {.surface = std::make_shared<const collette::MeshInside>(*collette::validate_mesh(mesh))});
  }
  void bind() { proxy_->bind(); }

  // one collision step towards the handle at time t
  void step(const Pose& handle, double t) {
    proxy_->set_target(handle);
    world_->step(t);
  }
  // one haptic tick: the wrench sent to the device (world frame: the mapping is the identity)
  forcecomp::Wrench tick(const Pose& handle, double t) {
    proxy_->set_target(handle);
    haptico::DeviceState s{.time_s = t, .position = handle.position, .orientation = handle.rotation};
    s.status = haptico::DeviceStatus::kOk;
    haptico::DeviceCommand command{};
    controller_->on_force(s, command);
    return {command.force, command.torque};
  }

  const ToolProxy& proxy() const { return *proxy_; }
  const Pose& rendered() const { return controller_->rendered_proxy(); }
  // the springs the controller renders: K [N/m] and K_r [N m/rad]
  double stiffness() const { return forcecomp::VirtualCoupling(options_.coupling).stiffness(); }
  double angular_stiffness() const {
    return forcecomp::VirtualCoupling(options_.coupling)
        .angular_stiffness_for(stiffness(), proxy_->radius_m());
  }

 private:
  std::unique_ptr<collette::CollisionWorld> world_;
  std::shared_ptr<const collette::SphereTree> tool_tree_;
  ForceControllerOptions options_;
  collette::ObjectId tool_ = -1;
  std::unique_ptr<ToolProxy> proxy_;
  std::unique_ptr<ForceController> controller_;
};

// the slab of the face tests: 10 x 10 x 2 cm, its top face at z = 0
collette::TriangleMesh slab_mesh() {
  collette::TriangleMesh m = box_mesh({0.1, 0.1, 0.02});
  for (Vec3& v : m.vertices) v.z -= 0.01;
  return m;
}

// the rod tool: 4 x 1 x 1 cm along x, centred on its origin
constexpr double kRodLength = 0.04, kRodThickness = 0.01;

Pose pose_of(const Quat& rotation, const Vec3& position) { return Pose{rotation, position}; }

struct Press {
  Vec3 force{}, torque{};  // the mean wrench sent over the last 100 ticks [N], [N m]
  Pose proxy{};            // the proxy at the end
};

// Lowers the rod, turned by `tilt` about y (its +x end down), onto the slab's face at 5 cm/s until
// the handle is `depth` below where the rod's lowest edge would touch the face, and holds it there.
Press press_rod(const Packed& slab, const Packed& rod, double tilt, double depth) {
  ProxyRig rig(rod);
  rig.add_object(slab_mesh(), slab);
  rig.bind();
  const Quat turn = quat_from_axis_angle({0, 1, 0}, tilt);
  const double touch = 0.5 * kRodLength * std::sin(std::abs(tilt)) + 0.5 * kRodThickness * std::cos(tilt);
  Press press;
  for (int i = 0; i < 1500; ++i) {
    const double t = 1e-3 * i;
    const Pose handle = pose_of(turn, {0.0, 0.0, std::max(0.03 - 0.00005 * i, touch - depth)});
    rig.step(handle, t);
    const forcecomp::Wrench w = rig.tick(handle, t);
    if (i >= 1400) {
      press.force += w.force / 100.0;
      press.torque += w.torque / 100.0;
    }
  }
  press.proxy = rig.proxy().pose();
  return press;
}

// (a) A rod pressed onto a packed face with its end: the torque felt is the moment of the force
// felt about the tool's centre, r x F, for the contact point the geometry predicts (the midpoint
// of the rod's lowest edge at the proxy's pose, which must lie on the face), within 10 %; pressed
// flat and centred, the centre of pressure is within the packing's unevenness (2 mm) of the centre.
TEST(ProxyTorque, AnOffsetPressFeelsTheMomentOfItsForceAboutTheToolsCentre) {
  const Packed slab = pack(slab_mesh(), 10000);
  const Packed rod = pack(box_mesh({kRodLength, kRodThickness, kRodThickness}), 2000);
  const double tilt = 10.0 * kPi / 180.0;
  const Press end = press_rod(slab, rod, tilt, 0.0015);
  const Vec3 lever = rotate(end.proxy.rotation, Vec3{0.5 * kRodLength, 0.0, -0.5 * kRodThickness});
  const Vec3 moment = cross(lever, end.force);
  std::printf(
      "end press: force (%.3f, %.3f, %.3f) N, torque (%.4f, %.4f, %.4f) N m, r x F (%.4f, %.4f, %.4f) N m, "
      "contact point %.3f mm from the face, rod turned back %.2f deg\n",
      end.force.x, end.force.y, end.force.z, end.torque.x, end.torque.y, end.torque.z, moment.x, moment.y,
      moment.z, (end.proxy.position.z + lever.z) * 1e3,
      (tilt - forcecomp::rotation_vector(end.proxy.rotation).y) * 180.0 / kPi);
  EXPECT_GT(end.force.z, 1.0) << "the rod is pressed onto the face";
  EXPECT_NEAR(end.proxy.position.z + lever.z, 0.0, rod.max_gap + 1e-4)
      << "the predicted point is on the face";
  EXPECT_GT(std::abs(moment.y), 0.015);
  EXPECT_LT(norm(end.torque - moment), 0.1 * norm(moment));

  const Press flat = press_rod(slab, rod, 0.0, 0.0015);
  const double centre_of_pressure = norm(flat.torque) / norm(flat.force);
  std::printf("centred press: force %.3f N, torque %.5f N m, centre of pressure %.2f mm from the centre\n",
              norm(flat.force), norm(flat.torque), centre_of_pressure * 1e3);
  EXPECT_GT(flat.force.z, 1.0);
  EXPECT_LT(centre_of_pressure, 0.002);
}

// A 10 mm square hole through a 6 x 6 x 2 cm plate, the plate's top face at z = 0: one closed mesh
// of genus one (the rings of the top and the bottom, the outer walls and the hole's walls).
collette::TriangleMesh plate_with_hole(double outer_half, double hole_half, double thickness) {
  collette::TriangleMesh m;
  m.source_name = "plate with a hole";
  const double corners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};  // counter-clockwise from above
  // vertices: outer top 0-3, inner top 4-7, outer bottom 8-11, inner bottom 12-15
  for (const double z : {0.0, -thickness})
    for (const double half : {outer_half, hole_half})
      for (const auto& c : corners) m.vertices.push_back({c[0] * half, c[1] * half, z});
  const auto quad = [&](std::int32_t a, std::int32_t b, std::int32_t c, std::int32_t d) {
    m.triangles.push_back({a, b, c});
    m.triangles.push_back({a, c, d});
  };
  for (std::int32_t k = 0; k < 4; ++k) {
    const std::int32_t n = (k + 1) % 4;
    quad(k, n, 4 + n, 4 + k);            // top ring, up
    quad(8 + k, 12 + k, 12 + n, 8 + n);  // bottom ring, down
    quad(8 + k, 8 + n, n, k);            // outer wall, out
    quad(12 + n, 12 + k, 4 + k, 4 + n);  // the hole's wall, into the hole
  }
  return m;
}

// (b) A square peg (10 x 10 x 40 mm, packed) pressed onto the plate beside the hole, slid over the
// hole's edge, pushed 0.5 mm against its far wall and down through it at 2 cm/s: it goes in to
// the depth the hand asks, the proxy's progress along the hole's axis keeps up with the hand's
// (every 20 ms at least half of it: no snag on the walls' packing gaps), and no peg sphere ever
// overlaps a plate sphere by more than the allowed penetration (brute force over every pair).
TEST(ProxyTorque, APegSlidesOverTheEdgeIntoAHoleAndDownItWithoutSnagging) {
  constexpr double kHole = 0.006, kThickness = 0.02, kPegHalf = 0.005, kPegHalfLength = 0.02;
  const collette::TriangleMesh plate_mesh = plate_with_hole(0.03, kHole, kThickness);
  const Packed plate = pack(plate_mesh, 10000);
  const Packed peg = pack(box_mesh({2 * kPegHalf, 2 * kPegHalf, 2 * kPegHalfLength}), 3000);
  ProxyRig rig(peg);
  rig.add_object(plate_mesh, plate);
  rig.bind();
  const double penetration = ToolProxyOptions{}.penetration_m;
  const double pressed_z = kPegHalfLength - 0.002;  // the handle 2 mm below the peg resting on the face
  const double lowest_handle_z = -0.012;            // the peg's bottom 32 mm down: through the plate
  double deepest = 0.0, worst_progress = 1e9, largest_torque = 0.0;
  double window_start_proxy = 0.0, window_start_handle = 0.0;
  constexpr int kDown = 1800, kWindow = 20;
  for (int i = 0; i < 3600; ++i) {
    const double t = 1e-3 * i;
    Vec3 h;
    if (i < 600)  // down onto the face beside the hole, at 5 cm/s
      h = {-0.015, 0.0, std::max(0.04 - 0.00005 * i, pressed_z)};
    else if (i < kDown)  // along the face over the hole's edge at 2 cm/s, to 0.5 mm past the far wall
      h = {std::min(-0.015 + 0.00002 * (i - 600), kHole - kPegHalf + 0.0005), 0.0, pressed_z};
    else  // down the hole at 2 cm/s
      h = {kHole - kPegHalf + 0.0005, 0.0, std::max(pressed_z - 0.00002 * (i - kDown), lowest_handle_z)};
    const Pose handle = pose_of(Quat{}, h);
    rig.step(handle, t);
    largest_torque = std::max(largest_torque, norm(rig.tick(handle, t).torque));
    const Pose& now = rig.proxy().pose();
    if (i % 100 == 0 || i == 3599)
      deepest = std::max(deepest, deepest_overlap(*plate.tree, Pose{}, *peg.tree, now));
    // inside the hole, while the handle descends: the proxy's descent over each window
    const bool inside = now.position.z - kPegHalfLength < -0.002 && h.z > lowest_handle_z;
    if (i >= kDown && (i - kDown) % kWindow == 0) {
      if (inside && i > kDown)
        worst_progress =
            std::min(worst_progress, (window_start_proxy - now.position.z) / (window_start_handle - h.z));
      window_start_proxy = now.position.z;
      window_start_handle = h.z;
    }
  }
  const double bottom = rig.proxy().pose().position.z - kPegHalfLength;
  std::printf(
      "peg through the hole: bottom %.2f mm below the face (the handle asks %.2f mm), slowest progress %.2f "
      "of "
      "the hand's, deepest overlap %.4f mm, largest torque %.4f N m, %llu unsolved\n",
      -bottom * 1e3, -(lowest_handle_z - kPegHalfLength) * 1e3, worst_progress, deepest * 1e3, largest_torque,
      static_cast<unsigned long long>(rig.proxy().stats().unsolved));
  EXPECT_LT(bottom, lowest_handle_z - kPegHalfLength + 0.002) << "the peg snagged above the depth asked";
  EXPECT_LT(worst_progress, 1e9) << "the peg never went in";
  EXPECT_GT(worst_progress, 0.5) << "the proxy stalled in the hole";
  EXPECT_LT(deepest, penetration + 1e-5);
  EXPECT_GT(largest_torque, 0.0) << "pressed against the wall's edge, the peg is turned";
}

// (c) Turning the handle near and into contact at 1 rad/s (the rod above the face pitched down
// until its end presses, turned about the vertical while pressed, pitched the other way so the
// contact switches ends) with four haptic ticks per collision step: per tick, the torque changes by
// at most 2 K_r w T and the force by at most 2 K R w T (a point at the tool's extent moves R w T),
// the rotational analogue of the force's K v T bound, and the proxy turns by at most twice the
// handle's turn over a collision step (pressed by its end while the hand turns about the vertical,
// it is held by six rows between steps and turns at each step: measured 0.63 of that turn).
TEST(ProxyTorque, TurningIntoContactChangesTheTorqueByAtMostKrWTPerTick) {
  const Packed slab = pack(slab_mesh(), 10000);
  const Packed rod = pack(box_mesh({kRodLength, kRodThickness, kRodThickness}), 2000);
  constexpr int kTicksPerStep = 4;
  constexpr double kHapticPeriod = 1e-3 / kTicksPerStep, kRate = 1.0;  // [s], [rad/s]
  ProxyRig rig(rod, 1.0 / kHapticPeriod);
  rig.add_object(slab_mesh(), slab);
  rig.bind();
  // the rod's end touches the face at 5 degrees of pitch
  const double touch =
      0.5 * kRodLength * std::sin(5.0 * kPi / 180.0) + 0.5 * kRodThickness * std::cos(5.0 * kPi / 180.0);
  const double step = kRate * kHapticPeriod;
  // pitch 0 -> 0.3 rad, yaw 0 -> 0.5 rad, pitch 0.3 -> -0.3 rad, each at 1 rad/s
  const auto orientation_at = [&](int tick) {
    const double a = step * tick;
    const double pitch = a < 0.3 ? a : a < 0.8 ? 0.3 : std::max(0.3 - (a - 0.8), -0.3);
    const double yaw = a < 0.3 ? 0.0 : std::min(a - 0.3, 0.5);
    return quat_from_axis_angle({0, 0, 1}, yaw) * quat_from_axis_angle({0, 1, 0}, pitch);
  };
  const int ticks = static_cast<int>(1.5 / step);
  forcecomp::Wrench last{};
  Quat last_proxy{};
  double largest_torque = 0.0, torque_step = 0.0, force_step = 0.0, proxy_turn = 0.0;
  for (int k = 0; k < ticks; ++k) {
    const double t = kHapticPeriod * k;
    const Pose handle = pose_of(orientation_at(k), {0.0, 0.0, touch});
    if (k % kTicksPerStep == 0) rig.step(handle, t);
    const forcecomp::Wrench w = rig.tick(handle, t);
    if (k > 0) {
      torque_step = std::max(torque_step, norm(w.torque - last.torque));
      force_step = std::max(force_step, norm(w.force - last.force));
      const double turn = norm(forcecomp::rotation_vector(rig.rendered().rotation * conjugate(last_proxy)));
      proxy_turn = std::max(proxy_turn, turn);
    }
    largest_torque = std::max(largest_torque, norm(w.torque));
    last = w;
    last_proxy = rig.rendered().rotation;
  }
  const double k_r = rig.angular_stiffness(), radius = rig.proxy().radius_m();
  std::printf(
      "turning into contact: K_r %.3f N m/rad (R %.1f mm), largest torque %.4f N m; per tick: torque %.6f "
      "N m (K_r w T %.6f), force %.5f N (K R w T %.5f), proxy turn %.5f rad (w T over a collision step "
      "%.5f)\n",
      k_r, radius * 1e3, largest_torque, torque_step, k_r * step, force_step, rig.stiffness() * radius * step,
      proxy_turn, kTicksPerStep * step);
  EXPECT_GT(largest_torque, 0.03) << "the rod was turned into the face";
  EXPECT_LE(torque_step, 2.0 * k_r * step);
  EXPECT_LE(force_step, 2.0 * rig.stiffness() * radius * step);
  EXPECT_LE(proxy_turn, 2.0 * kTicksPerStep * step);
}

// A hand that turns the handle about one axis (y), reacting to the torque the device sends:
// inertia, a spring-damper to a target angle that sweeps back and forth, the device's own
// rotational damping, and the commanded torque held over each period (as a servo loop holds it).
// The sim-hand device moves only in translation (its orientation stays the identity), so this
// test integrates the rotation itself.
struct TurningHand {
  double inertia = 2e-4;             // [kg m^2]
  double stiffness = 0.5;            // [N m/rad]
  double damping = 5e-3;             // [N m s/rad]
  double device_damping = 1e-3;      // the mechanism's own b_r [N m s/rad]
  double angle = 0.0, rate = 0.0;    // [rad], [rad/s]
  double work_j = 0.0;               // the motors' work on the hand [J]
  double damped_in_contact_j = 0.0;  // what the mechanism dissipates while a torque is sent [J]

  void advance(double target, double target_rate, double torque, double period, int substeps) {
    const double dt = period / substeps;
    for (int i = 0; i < substeps; ++i) {
      rate +=
          dt / inertia *
          (stiffness * (target - angle) + damping * (target_rate - rate) - device_damping * rate + torque);
      angle += dt * rate;
      work_j += torque * rate * dt;
      if (torque != 0.0) damped_in_contact_j += device_damping * rate * rate * dt;
    }
  }
};

// The energy a turning hand gets from the device over four closed sweeps that press the rod's
// end into the face and lift it off [J]: the motors' work less what the mechanism dissipates in
// contact. `options` is what the coupling is told; the hand's mechanism is b_r = 1e-3.
double energy_into_turning_hand(const Packed& slab, const Packed& rod,
                                const ForceControllerOptions& options) {
  ProxyRig rig(rod, 1000.0, options);
  rig.add_object(slab_mesh(), slab);
  rig.bind();
  const double touch =
      0.5 * kRodLength * std::sin(5.0 * kPi / 180.0) + 0.5 * kRodThickness * std::cos(5.0 * kPi / 180.0);
  TurningHand hand;
  const double period = 1e-3, sweep_s = 0.5, low = 0.0, high = 0.35;
  double torque = 0.0;
  for (int i = 0; i < 4000; ++i) {
    const double t = period * i;
    const double phase = std::fmod(t, 2.0 * sweep_s) / sweep_s;  // 0..2: up, then down
    const double target = low + (high - low) * (phase < 1.0 ? phase : 2.0 - phase);
    const double target_rate = (high - low) / sweep_s * (phase < 1.0 ? 1.0 : -1.0);
    const Pose handle = pose_of(quat_from_axis_angle({0, 1, 0}, hand.angle), {0.0, 0.0, touch});
    rig.step(handle, t);
    torque = rig.tick(handle, t).torque.y;
    hand.advance(target, target_rate, torque, period, 20);
  }
  std::printf(
      "turning hand (K_r %.3f N m/rad, bound %.3f): motors' work %+.4f mJ, damped in contact %.4f mJ, into "
      "the hand %+.4f mJ\n",
      rig.angular_stiffness(), forcecomp::VirtualCoupling(options.coupling).angular_stiffness_bound(),
      hand.work_j * 1e3, hand.damped_in_contact_j * 1e3, (hand.work_j - hand.damped_in_contact_j) * 1e3);
  return hand.work_j - hand.damped_in_contact_j;
}

// (d) Passivity of the angular coupling: with the default torque spring (K R^2, within Colgate's
// bound for the device's rotational damping at the haptic period) a hand that turns the rod's
// end into the face and out again, four times, gets no energy from the device; told ten times the
// mechanism's damping and asked for a spring at that bound, the same sweeps put energy into it.
TEST(ProxyTorque, ATurningHandGetsNoEnergyFromTheTorqueSpring) {
  const Packed slab = pack(slab_mesh(), 10000);
  const Packed rod = pack(box_mesh({kRodLength, kRodThickness, kRodThickness}), 2000);
  EXPECT_LE(energy_into_turning_hand(slab, rod, {}), 0.0);
  ForceControllerOptions too_stiff;
  too_stiff.coupling.device_angular_damping = 1e-2;
  too_stiff.coupling.angular_stiffness = 18.0;
  EXPECT_GT(energy_into_turning_hand(slab, rod, too_stiff), 1e-4)
      << "the measure catches a spring past the bound";
}

// The default configuration (no coupling field set): a 6-DOF tool on a device that actuates six
// degrees of freedom feels the proxy's torques; on a 3-DOF device it gets none. The small scene's
// stylus pressed into the bunny through the proxy, the device's dof_actuated 6, then 3.
TEST(ProxyTorque, ASixDofDeviceFeelsTheProxysTorqueByDefaultAndAThreeDofDeviceNone) {
  const std::filesystem::path cache = testing::fresh_cache("proxy_torque");
  double largest[2] = {};
  for (const int dof : {6, 3}) {
    const std::string json = testing::replaced(testing::small_scene_json(), "\"dof_actuated\": 6",
                                               "\"dof_actuated\": " + std::to_string(dof));
    auto scene = parse_scene(json, "small.json", testing::test_assets());
    ASSERT_TRUE(scene) << scene.error().message;
    ASSERT_TRUE(scene->force.proxy.enabled);
    ASSERT_FALSE(scene->force.coupling.angular_stiffness) << "the default: derived from the linear spring";
    SessionOptions options;
    options.cache_dir = cache;
    auto session = HapticSession::create(*scene, options);
    ASSERT_TRUE(session) << session.error().message;
    ASSERT_TRUE((*session)->run_stepped(1.0, 1).has_value());
    const SessionReport& r = (*session)->report();
    EXPECT_GT(r.force_max_n, 0.5) << dof << " DOF: the stylus is pushed out";
    largest[dof == 6 ? 0 : 1] = r.torque_max_nm;
  }
  std::printf("largest torque sent: %.4f N m to a 6-DOF device, %.4f N m to a 3-DOF one\n", largest[0],
              largest[1]);
  EXPECT_GT(largest[0], 1e-3);
  EXPECT_EQ(largest[1], 0.0);
  std::filesystem::remove_all(cache);
}

}  // namespace
}  // namespace uh::controllers
