// The whole chain on a real mesh: a single-sphere tool pressed into the packed bunny. The force the
// collision world and ForceComp produce equals eq. 1 summed by hand over every bunny leaf sphere.
#include <gtest/gtest.h>

#include <memory>

#include "lens_reference.hpp"
#include "scene_test_support.hpp"
#include "uh/collette/collision_world.hpp"
#include "uh/collette/sphere_tree_builder.hpp"
#include "uh/controllers/scene.hpp"
#include "uh/forcecomp/force_component.hpp"

namespace uh::controllers {
namespace {

TEST(SphereBunnyForce, WorldAndForceComponentMatchTheSumOverAllLeaves) {
  const auto cache = testing::fresh_cache("sphere-bunny");
  const SceneShape bunny_shape{.mesh = testing::test_assets() / "meshes" / "bunny_npm_3674.obj", .spheres = 800,
                               .meters_per_unit = 0.01};
  const auto bunny = load_shape_tree(bunny_shape, cache);
  ASSERT_TRUE(bunny.has_value()) << bunny.error().message;
  const Sphere probe{0.f, 0.f, 0.f, 0.01f};  // a 1 cm ball
  const auto probe_tree = collette::build_sphere_tree(std::vector<Sphere>{probe});
  ASSERT_TRUE(probe_tree.has_value());

  collette::CollisionWorld world;
  const Pose bunny_pose{quat_from_axis_angle({1, 0, 0}, kPi / 2), {}};  // mesh y-up -> world z-up
  const auto a = world.add_object({.tree = *bunny, .world_from_object = bunny_pose, .name = "bunny"});
  const auto b = world.add_object({.tree = std::make_shared<const collette::SphereTree>(*probe_tree), .name = "probe"});
  ASSERT_TRUE(a && b);
  const auto watcher = world.add_collision_watcher(*a, *b);
  ASSERT_TRUE(watcher.has_value());

  const forcecomp::ForceComponent component({.params = {.force_scale = 1.0e6, .damping = 0.0}});
  auto frame = std::make_unique<ContactFrame>();
  int poses_in_contact = 0;
  for (double z : {0.02, 0.035, 0.05}) {
    const Pose probe_pose{{}, {0.005, -0.003, z}};
    world.set_pose(*b, probe_pose);
    world.step(z);
    ASSERT_TRUE(world.read_contact(*watcher, *frame));
    const auto result = component.evaluate(*frame, component.body_motion(probe_pose, {}, {}));

    // by hand: eq. 1 without damping is eps_c * sum over bunny leaves of lens volume * unit normal
    Vec3 expected{};
    for (const Sphere& leaf : (*bunny)->leaves()) {
      const Vec3 c = transform_point(bunny_pose, Vec3{leaf.x, leaf.y, leaf.z});
      const Vec3 d = probe_pose.position - c;
      const double v = uh::test::lens_reference(norm(d), leaf.radius, probe.radius).volume;
      if (v > 0.0) expected += 1.0e6 * v * normalized(d);
    }
    if (norm(expected) > 0.0) ++poses_in_contact;
    EXPECT_NEAR(result.wrench.force.x, expected.x, 1e-4 * norm(expected) + 1e-9);
    EXPECT_NEAR(result.wrench.force.y, expected.y, 1e-4 * norm(expected) + 1e-9);
    EXPECT_NEAR(result.wrench.force.z, expected.z, 1e-4 * norm(expected) + 1e-9);
    // a sphere has no lever: the lens centroids lie on the lines through its centre
    EXPECT_LT(norm(result.wrench.torque), 1e-6 + 1e-4 * norm(expected) * 0.01);
  }
  EXPECT_GE(poses_in_contact, 2) << "the probe must actually be inside the bunny";
  std::filesystem::remove_all(cache);
}

}  // namespace
}  // namespace uh::controllers
