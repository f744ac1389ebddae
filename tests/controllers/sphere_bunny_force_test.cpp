// The whole chain on a real mesh: a single-sphere tool pressed into the packed bunny. The force the
// collision world and ForceComp produce equals each law summed by hand over every bunny leaf sphere.
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
  const auto a = world.add_object({.tree = bunny->tree, .world_from_object = bunny_pose, .name = "bunny"});
  const auto b = world.add_object({.tree = std::make_shared<const collette::SphereTree>(*probe_tree), .name = "probe"});
  ASSERT_TRUE(a && b);
  const auto watcher = world.add_collision_watcher(*a, *b);
  ASSERT_TRUE(watcher.has_value());

  const forcecomp::ForceComponent paper(
      {.params = {.law = forcecomp::ForceLaw::kPaper, .force_scale = 1.0e6, .damping = 0.0}});
  const forcecomp::ForceComponent gradient({.params = {.stiffness = 2.0e4, .damping = 0.0}});
  // the probe is one sphere: its coverage is 1
  const double coverage_product = bunny->coverage;
  auto frame = std::make_unique<ContactFrame>();
  int poses_in_contact = 0;
  for (double z : {0.02, 0.035, 0.05}) {
    const Pose probe_pose{{}, {0.005, -0.003, z}};
    world.set_pose(*b, probe_pose);
    world.step(z);
    ASSERT_TRUE(world.read_contact(*watcher, *frame));
    const auto motion = paper.body_motion(probe_pose, {}, {});
    const auto by_volume = paper.evaluate(*frame, motion);
    const auto by_gradient = gradient.evaluate(*frame, motion, {}, coverage_product);

    // by hand: eq. 1 without damping is eps_c * sum over bunny leaves of lens volume * unit normal;
    // the gradient law k / c * sum of intersection disk area * unit normal
    Vec3 expected_paper{}, expected_gradient{};
    for (const Sphere& leaf : bunny->tree->leaves()) {
      const Vec3 c = transform_point(bunny_pose, Vec3{leaf.x, leaf.y, leaf.z});
      const Vec3 d = probe_pose.position - c;
      const auto lens = uh::test::lens_reference(norm(d), leaf.radius, probe.radius);
      if (lens.volume > 0.0) {
        expected_paper += 1.0e6 * lens.volume * normalized(d);
        expected_gradient += 2.0e4 / coverage_product * lens.area * normalized(d);
      }
    }
    if (norm(expected_paper) > 0.0) ++poses_in_contact;
    for (const auto& [result, expected] :
         {std::pair{by_volume, expected_paper}, std::pair{by_gradient, expected_gradient}}) {
      EXPECT_NEAR(result.wrench.force.x, expected.x, 1e-4 * norm(expected) + 1e-9);
      EXPECT_NEAR(result.wrench.force.y, expected.y, 1e-4 * norm(expected) + 1e-9);
      EXPECT_NEAR(result.wrench.force.z, expected.z, 1e-4 * norm(expected) + 1e-9);
      // a sphere has no lever: the lens centroids lie on the lines through its centre
      EXPECT_LT(norm(result.wrench.torque), 1e-6 + 1e-4 * norm(expected) * 0.01);
    }
  }
  EXPECT_GE(poses_in_contact, 2) << "the probe must actually be inside the bunny";
  std::filesystem::remove_all(cache);
}

}  // namespace
}  // namespace uh::controllers
