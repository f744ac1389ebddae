#include "uh/collette/collision_world.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <thread>
#include <vector>

#include "lens_reference.hpp"
#include "uh/collette/sphere_tree_builder.hpp"

namespace uh::collette {
namespace {

// A cube of side `n * 2r` filled with an n^3 lattice of touching, non-overlapping spheres.
std::vector<Sphere> lattice_block(int n, float r) {
  std::vector<Sphere> spheres;
  const float offset = -static_cast<float>(n - 1) * r;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k)
        spheres.push_back({offset + 2.f * r * static_cast<float>(i), offset + 2.f * r * static_cast<float>(j),
                           offset + 2.f * r * static_cast<float>(k), r * 0.999f});
  return spheres;
}

std::shared_ptr<const SphereTree> make_tree(const std::vector<Sphere>& leaves) {
  auto tree = build_sphere_tree(leaves);
  EXPECT_TRUE(tree.has_value());
  return std::make_shared<const SphereTree>(std::move(tree).value());
}

// Sum of lens volumes over all leaf pairs at the given world poses.
double brute_force_volume(const std::vector<Sphere>& a, const Pose& world_from_a, const std::vector<Sphere>& b,
                          const Pose& world_from_b) {
  double total = 0.0;
  for (const Sphere& sa : a) {
    const Vec3 ca = transform_point(world_from_a, {sa.x, sa.y, sa.z});
    for (const Sphere& sb : b) {
      const Vec3 cb = transform_point(world_from_b, {sb.x, sb.y, sb.z});
      total += uh::test::lens_reference(norm(cb - ca), sa.radius, sb.radius).volume;
    }
  }
  return total;
}

struct WorldFixture : ::testing::Test {
  std::vector<Sphere> leaves = lattice_block(6, 0.05f);
  std::shared_ptr<const SphereTree> tree = make_tree(leaves);
};

TEST_F(WorldFixture, RejectsBadSetup) {
  CollisionWorld world;
  EXPECT_FALSE(world.add_object({.tree = nullptr, .name = "empty"}).has_value());
  const auto a = world.add_object({.tree = tree, .name = "a"});
  const auto b = world.add_object({.tree = tree, .name = "b"});
  ASSERT_TRUE(a && b);
  EXPECT_FALSE(world.start().has_value()) << "start without a watcher must fail";
  EXPECT_FALSE(world.add_collision_watcher(*a, *a).has_value());
  EXPECT_FALSE(world.add_collision_watcher(*a, 7).has_value());
  EXPECT_TRUE(world.add_collision_watcher(*a, *b).has_value());
  const auto again = world.add_collision_watcher(*b, *a);
  ASSERT_FALSE(again.has_value());
  EXPECT_NE(again.error().message.find("watched already"), std::string::npos);
}

TEST_F(WorldFixture, StepMatchesBruteForceAndBroadcastsContactAndItsEnd) {
  CollisionWorld world;
  const Pose pose_a{};
  const Pose touching{quat_from_axis_angle({0, 1, 0}, 0.3), {0.45, 0.02, -0.01}};
  const Pose apart{{}, {2.0, 0.0, 0.0}};
  const ObjectId a = *world.add_object({.tree = tree, .world_from_object = pose_a, .name = "a"});
  const ObjectId b = *world.add_object({.tree = tree, .world_from_object = touching, .name = "b"});
  const WatcherId w = *world.add_collision_watcher(a, b);

  std::vector<double> volumes;
  std::vector<int> pair_counts;
  auto connection = world.on_collision().connect([&](ObjectId ia, ObjectId ib, const ContactFrame& frame) {
    EXPECT_EQ(ia, a);
    EXPECT_EQ(ib, b);
    volumes.push_back(frame.total_volume);
    pair_counts.push_back(frame.pair_count);
  });

  world.step(0.0);
  auto frame = std::make_unique<ContactFrame>();
  ASSERT_TRUE(world.read_contact(w, *frame));
  const double expected = brute_force_volume(leaves, pose_a, leaves, touching);
  ASSERT_GT(expected, 0.0);
  EXPECT_NEAR(frame->total_volume, expected, 1e-4 * expected);
  EXPECT_EQ(frame->sequence, 1u);
  EXPECT_GT(frame->pair_count, 0);
  // lattice-on-lattice pair normals are noisy, but their volume-weighted sum must point out of A (+x)
  EXPECT_GT(frame->restoring_direction_world.x, 0.0) << "B sits at +x of A, so it is pushed towards +x";
  EXPECT_NEAR(norm(frame->restoring_direction_world), 1.0, 1e-9);
  // the volume shrinks when B moves out along +x
  EXPECT_LT(frame->volume_gradient_world.x, 0.0);
  EXPECT_FALSE(world.read_contact(w, *frame)) << "no newer frame yet";

  world.set_pose(b, apart);
  world.step(0.001);
  ASSERT_TRUE(world.read_contact(w, *frame));
  EXPECT_EQ(frame->pair_count, 0);
  EXPECT_EQ(frame->total_volume, 0.0);
  // separation of the packings: lattice half-width is 0.3 (minus the 0.1% shrink), so about 1.4
  EXPECT_GT(frame->distance, 1.35);
  EXPECT_LT(frame->distance, 1.45);

  world.step(0.002);  // still apart: no further broadcast
  ASSERT_EQ(volumes.size(), 2u) << "one broadcast in contact, one when the contact ended";
  EXPECT_NEAR(volumes[0], expected, 1e-4 * expected);
  EXPECT_EQ(pair_counts[1], 0);

  const CollisionWorldStats stats = world.stats();
  EXPECT_EQ(stats.steps, 3u);
  EXPECT_EQ(stats.queries, 1u) << "the broad phase skips the apart steps";
  EXPECT_EQ(stats.contact_frames, 1u);
}

TEST_F(WorldFixture, CoherentWatchersDeliverTheSameFramesAsTraversingOnes) {
  // two watched pairs (B and C against A) in a world with a coherence skin, against the same
  // scene in a world without: every frame must agree, along small steps and a jump
  CollisionWorld plain({.contact_margin = 0.01});
  CollisionWorld coherent({.contact_margin = 0.01, .coherence_skin = 0.02});
  const auto other = make_tree(lattice_block(4, 0.04f));
  std::vector<WatcherId> watchers[2];
  CollisionWorld* worlds[2] = {&plain, &coherent};
  for (int k = 0; k < 2; ++k) {
    CollisionWorld& w = *worlds[k];
    const ObjectId a = *w.add_object({.tree = tree, .name = "a"});
    const ObjectId b = *w.add_object({.tree = tree, .world_from_object = {{}, {0.5, 0.0, 0.0}}, .name = "b"});
    const ObjectId c = *w.add_object({.tree = other, .world_from_object = {{}, {0.0, 0.4, 0.0}}, .name = "c"});
    watchers[k] = {*w.add_collision_watcher(a, b), *w.add_collision_watcher(a, c)};
  }
  auto frame_plain = std::make_unique<ContactFrame>();
  auto frame_coherent = std::make_unique<ContactFrame>();
  int touching = 0;
  for (int step = 0; step < 120; ++step) {
    const double t = 0.001 * step;
    const double jump = step == 60 ? 0.2 : 0.0;
    const Pose pb{quat_from_axis_angle({0, 0, 1}, 0.2 * t), {0.5 - 0.3 * t + jump, 0.01 * (step % 3), 0.0}};
    const Pose pc{quat_from_axis_angle({1, 0, 0}, 0.5 * t), {0.0, 0.4 - 0.5 * t, 0.002 * step}};
    for (CollisionWorld* w : worlds) {
      w->set_pose(1, pb);
      w->set_pose(2, pc);
      w->step(t);
    }
    for (int i = 0; i < 2; ++i) {
      ASSERT_TRUE(plain.read_contact(watchers[0][static_cast<std::size_t>(i)], *frame_plain));
      ASSERT_TRUE(coherent.read_contact(watchers[1][static_cast<std::size_t>(i)], *frame_coherent));
      ASSERT_EQ(frame_coherent->pair_count, frame_plain->pair_count) << "step " << step << " watcher " << i;
      EXPECT_NEAR(frame_coherent->total_volume, frame_plain->total_volume, 1e-12 + 1e-9 * frame_plain->total_volume);
      if (frame_plain->total_volume > 0.0) ++touching;
    }
  }
  EXPECT_GT(touching, 150) << "the paths must stay mostly in contact";
  EXPECT_EQ(plain.stats().coherent_queries, 0u);
  EXPECT_GT(coherent.stats().coherent_queries, 150u) << "the small steps must reuse the kept candidates";
  EXPECT_LT(coherent.stats().coherent_queries, coherent.stats().queries) << "the jump must force a traversal";
}

TEST_F(WorldFixture, ThreadedWorldPublishesFramesForPosesSetFromAnotherThread) {
  CollisionWorld world({.rate_hz = 2000.0});
  const ObjectId a = *world.add_object({.tree = tree, .name = "a"});
  const ObjectId b = *world.add_object({.tree = tree, .world_from_object = Pose{{}, {3, 0, 0}}, .name = "b"});
  const WatcherId w = *world.add_collision_watcher(a, b);
  std::atomic<int> broadcasts{0};
  auto connection = world.on_collision().connect([&](ObjectId, ObjectId, const ContactFrame&) { ++broadcasts; });
  ASSERT_TRUE(world.start().has_value());
  EXPECT_FALSE(world.start().has_value()) << "second start must fail";

  // a mover thread sweeps B into A while this thread reads the frames
  std::atomic<bool> done{false};
  std::thread mover([&] {
    for (int i = 0; i <= 200 && !done; ++i) {
      world.set_pose(b, Pose{{}, {0.9 - 0.0025 * i, 0.0, 0.0}});
      std::this_thread::sleep_for(std::chrono::microseconds(500));
    }
  });
  auto frame = std::make_unique<ContactFrame>();
  std::uint64_t last_sequence = 0;
  double max_volume = 0.0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (std::chrono::steady_clock::now() < deadline) {
    if (world.read_contact(w, *frame)) {
      EXPECT_GT(frame->sequence, last_sequence);
      last_sequence = frame->sequence;
      max_volume = std::max(max_volume, frame->total_volume);
      if (frame->pair_count > 0 && last_sequence > 50) break;
    }
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  done = true;
  mover.join();
  world.stop();
  world.stop();
  EXPECT_FALSE(world.running());
  EXPECT_GT(max_volume, 0.0);
  EXPECT_GT(broadcasts.load(), 0);
  const CollisionWorldStats stats = world.stats();
  EXPECT_GT(stats.steps, 50u);
  EXPECT_GT(stats.queries, 0u);
  EXPECT_GT(stats.query_time.count, 0u);
}

TEST_F(WorldFixture, FreeRunningModeStartsAndStops) {
  CollisionWorld world({.rate_hz = 0.0});
  const ObjectId a = *world.add_object({.tree = tree, .name = "a"});
  const ObjectId b = *world.add_object({.tree = tree, .world_from_object = Pose{{}, {0.5, 0, 0}}, .name = "b"});
  ASSERT_TRUE(world.add_collision_watcher(a, b).has_value());
  ASSERT_TRUE(world.start().has_value());
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (world.stats().steps < 20 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  world.stop();
  EXPECT_GE(world.stats().steps, 20u);
  EXPECT_FALSE(world.running());
}

}  // namespace
}  // namespace uh::collette

namespace uh::collette {
namespace {

TEST_F(WorldFixture, AnObjectWithoutAPoseIsNotQueriedUntilItsMoverSetsOne) {
  CollisionWorld world;
  const ObjectId a = *world.add_object({.tree = tree, .name = "a"});
  // at the identity pose B would overlap A completely: it must not be reported before set_pose
  const ObjectId b = *world.add_object({.tree = tree, .has_initial_pose = false, .name = "tool"});
  const WatcherId w = *world.add_collision_watcher(a, b);
  auto frame = std::make_unique<ContactFrame>();
  world.step(0.0);
  EXPECT_FALSE(world.read_contact(w, *frame)) << "no frame before the tool has a pose";
  EXPECT_EQ(world.stats().queries, 0u);
  world.set_pose(b, Pose{{}, {0.5, 0.0, 0.0}});
  world.step(0.001);
  ASSERT_TRUE(world.read_contact(w, *frame));
  EXPECT_GT(frame->total_volume, 0.0);
}

}  // namespace
}  // namespace uh::collette
