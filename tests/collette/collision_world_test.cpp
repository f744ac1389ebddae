#include "uh/collette/collision_world.hpp"

#include <gtest/gtest.h>

#include <array>
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
  EXPECT_FALSE(world.add_object({.tree = tree, .coverage = 0.0, .name = "c"}).has_value());
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

// A deforming object (its trees published through `deformed_trees`, as a soft body's simulation
// does) under a coherent watcher: its leaves move while neither pose does, so the kept candidates
// of an earlier tree say nothing of the new one. Every frame must agree with a world that traverses.
TEST_F(WorldFixture, CoherentWatchersFollowADeformingTree) {
  CollisionWorld plain({.contact_margin = 0.01});
  CollisionWorld coherent({.contact_margin = 0.01, .coherence_skin = 0.02});
  LatestValue<SphereTree> trees[2];
  CollisionWorld* worlds[2] = {&plain, &coherent};
  WatcherId watchers[2]{};
  ObjectId tools[2]{};
  const Pose tool_pose{{}, {0.62, 0.0, 0.0}};
  for (int k = 0; k < 2; ++k) {
    const ObjectId soft = *worlds[k]->add_object({.tree = tree, .name = "soft", .deformed_trees = &trees[k]});
    tools[k] = *worlds[k]->add_object({.tree = tree, .world_from_object = tool_pose, .name = "tool"});
    watchers[k] = *worlds[k]->add_collision_watcher(soft, tools[k]);
  }
  auto frames = std::array{std::make_unique<ContactFrame>(), std::make_unique<ContactFrame>()};
  std::vector<Sphere> moved = leaves;
  int touching = 0;
  for (int step = 0; step < 35; ++step) {
    // the soft object swells towards the tool, its side 7.5 mm a step, to twice its width, so that
    // leaves far beyond the skin at first reach the tool (its poses stay where they are)
    for (std::size_t i = 0; i < moved.size(); ++i) moved[i].x = leaves[i].x * (1.f + 0.03f * static_cast<float>(step));
    for (int k = 0; k < 2; ++k) {
      SphereTree& next = trees[k].write_buffer();
      next = *tree;
      next.refit(moved);
      trees[k].publish();
      worlds[k]->set_pose(tools[k], tool_pose);
      worlds[k]->step(0.001 * step);
      ASSERT_TRUE(worlds[k]->read_contact(watchers[k], *frames[static_cast<std::size_t>(k)]));
    }
    ASSERT_EQ(frames[1]->pair_count, frames[0]->pair_count) << "step " << step;
    EXPECT_NEAR(frames[1]->total_volume, frames[0]->total_volume, 1e-12 + 1e-9 * frames[0]->total_volume);
    if (frames[0]->total_volume > 0.0) ++touching;
  }
  EXPECT_GT(touching, 20) << "the swelling object must reach the tool";
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

#include <random>
#include <set>

#include "uh/collette/dynamic_aabb_tree.hpp"

namespace uh::collette {
namespace {

TEST(DynamicAabbTree, QueriesMatchAllPairsThroughInsertsMovesAndRemoves) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> pos(-10.0, 10.0), size(0.1, 2.0), step(-0.6, 0.6);
  DynamicAabbTree tree(4);
  struct Item {
    Aabb box;
    std::int32_t proxy;
  };
  std::vector<Item> items;  // index = user value; proxy -1 once removed
  const auto random_box = [&] {
    const Vec3 c{pos(rng), pos(rng), pos(rng)};
    const double h = size(rng);
    return aabb::of_sphere(c, h);
  };
  const double margin = 0.3;
  for (int round = 0; round < 40; ++round) {
    for (int k = 0; k < 10; ++k) {
      const Aabb box = random_box();
      items.push_back({box, tree.create(box, margin, static_cast<std::int32_t>(items.size()))});
    }
    for (Item& it : items) {
      if (it.proxy < 0) continue;
      const Vec3 d{step(rng), step(rng), step(rng)};
      it.box = {it.box.min + d, it.box.max + d};
      tree.move(it.proxy, it.box, margin);
      ASSERT_TRUE(aabb::contains(tree.fat_box(it.proxy), it.box));
    }
    for (int k = 0; k < 4; ++k) {
      Item& it = items[std::uniform_int_distribution<std::size_t>(0, items.size() - 1)(rng)];
      if (it.proxy < 0) continue;
      tree.destroy(it.proxy);
      it.proxy = -1;
    }
    ASSERT_TRUE(tree.valid()) << "round " << round;
    // reference: every live item whose fat box overlaps the query box, by testing all of them
    for (int q = 0; q < 20; ++q) {
      const Aabb box = random_box();
      std::set<std::int32_t> expected, found;
      for (std::size_t i = 0; i < items.size(); ++i)
        if (items[i].proxy >= 0 && aabb::overlaps(tree.fat_box(items[i].proxy), box))
          expected.insert(static_cast<std::int32_t>(i));
      tree.query(box, [&](std::int32_t user) {
        EXPECT_TRUE(found.insert(user).second) << "reported twice";
        return true;
      });
      ASSERT_EQ(found, expected) << "round " << round << " query " << q;
      // and the fat boxes hold the tight ones, so no true overlap is missed
      for (std::size_t i = 0; i < items.size(); ++i)
        if (items[i].proxy >= 0 && aabb::overlaps(items[i].box, box)) {
          ASSERT_TRUE(found.count(static_cast<std::int32_t>(i)));
        }
    }
  }
  int live = 0;
  for (const Item& it : items) live += it.proxy >= 0 ? 1 : 0;
  EXPECT_EQ(tree.proxy_count(), live);
  // balanced: an AVL-like tree of n leaves is at most about 1.44 log2(n) + 2 high
  EXPECT_LE(tree.height(), static_cast<int>(1.45 * std::log2(static_cast<double>(live)) + 2.0));
}

TEST_F(WorldFixture, StaleIdsAreRefusedWithAMessageAndSlotsAreReusedUnderANewGeneration) {
  CollisionWorld world;
  const ObjectId a = *world.add_object({.tree = tree, .name = "a"});
  const ObjectId b = *world.add_object({.tree = tree, .world_from_object = {{}, {0.5, 0, 0}}, .name = "b"});
  const WatcherId w = *world.add_collision_watcher(a, b);
  const Status refused = world.remove_object(b);
  ASSERT_FALSE(refused.has_value());
  EXPECT_NE(refused.error().message.find("remove the watcher first"), std::string::npos)
      << refused.error().message;
  ASSERT_TRUE(world.remove_watcher(w).has_value());
  ASSERT_TRUE(world.remove_object(b).has_value());
  EXPECT_FALSE(world.contains(b));
  EXPECT_EQ(world.object_count(), 1);

  const ObjectId c = *world.add_object({.tree = tree, .name = "c"});
  EXPECT_NE(c, b) << "the reused slot carries a new generation";
  EXPECT_TRUE(world.contains(c));
  const Status again = world.remove_object(b);
  ASSERT_FALSE(again.has_value());
  EXPECT_NE(again.error().message.find("stale"), std::string::npos) << again.error().message;
  const auto watch_stale = world.add_collision_watcher(a, b);
  ASSERT_FALSE(watch_stale.has_value());
  EXPECT_NE(watch_stale.error().message.find("stale"), std::string::npos);
  EXPECT_FALSE(world.set_pose(b, Pose{})) << "a stale id must not move the slot's new object";
  EXPECT_EQ(world.stats().stale_poses, 1u);
  EXPECT_FALSE(world.remove_watcher(w).has_value());
  EXPECT_NE(world.remove_object(12345).error().message.find("no object"), std::string::npos);
  const ObjectId fixed = *world.add_object({.tree = tree, .is_static = true, .name = "fixed"});
  EXPECT_FALSE(world.set_pose(fixed, Pose{})) << "a static object does not move";
}

// Objects scattered in a room; the lens volumes of one object's leaves against the tool's, by
// testing every leaf pair (no tree, no broad phase).
struct Room {
  std::vector<Pose> poses;
  std::vector<ObjectId> ids;
};

TEST_F(WorldFixture, ToolAgainstEverythingMatchesBruteForcePerObject) {
  CollisionWorld world({.compute_distance = false});
  const auto small = make_tree(lattice_block(3, 0.05f));
  const std::vector<Sphere> small_leaves = lattice_block(3, 0.05f);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> coord(-1.0, 1.0), angle(0.0, 3.0);
  Room room;
  for (int i = 0; i < 40; ++i) {
    const Pose p{quat_from_axis_angle(normalized(Vec3{coord(rng), coord(rng), 1.0}), angle(rng)),
                 {coord(rng), coord(rng), 0.2 * coord(rng)}};
    room.poses.push_back(p);
    room.ids.push_back(*world.add_object(
        {.tree = small, .world_from_object = p, .is_static = i % 2 == 0, .coverage = 0.5, .name = "object"}));
  }
  const ObjectId tool =
      *world.add_object({.tree = tree, .has_initial_pose = false, .coverage = 0.8, .name = "tool"});
  const WatcherId w = *world.add_tool_watcher(tool);
  EXPECT_FALSE(world.add_tool_watcher(tool).has_value()) << "watched against everything already";
  auto frame = std::make_unique<ContactFrame>();
  int sections_seen = 0;
  for (int step = 0; step < 30; ++step) {
    const Pose tool_pose{quat_from_axis_angle({0, 0, 1}, 0.1 * step),
                         {-1.0 + 0.07 * step, 0.3 * std::sin(0.2 * step), 0.0}};
    ASSERT_TRUE(world.set_pose(tool, tool_pose));
    if (step == 15) {  // one object moves into the tool's path
      room.poses[1] = Pose{{}, tool_pose.position + Vec3{0.1, 0.0, 0.0}};
      ASSERT_TRUE(world.set_pose(room.ids[1], room.poses[1]));
    }
    world.step(0.001 * step);
    ASSERT_TRUE(world.read_contact(w, *frame));
    EXPECT_EQ(frame->object_a, ContactFrame::kEveryObject);
    EXPECT_EQ(frame->object_b, tool);
    double total = 0.0;
    std::set<ObjectId> in_frame;
    for (const ContactSection& s : frame->sections()) {
      in_frame.insert(s.object_a);
      EXPECT_EQ(s.object_b, tool);
      EXPECT_DOUBLE_EQ(s.coverage_product, 0.4);
      const auto i = static_cast<std::size_t>(std::find(room.ids.begin(), room.ids.end(), s.object_a) -
                                              room.ids.begin());
      ASSERT_LT(i, room.ids.size());
      const double expected = brute_force_volume(small_leaves, room.poses[i], leaves, tool_pose);
      EXPECT_NEAR(s.total_volume, expected, 1e-4 * expected + 1e-12);
      double pair_sum = 0.0;
      for (int k = 0; k < s.pair_count; ++k)
        pair_sum += static_cast<double>(frame->pairs()[static_cast<std::size_t>(s.first_pair + k)].volume);
      EXPECT_NEAR(pair_sum, s.total_volume, 1e-4 * s.total_volume + 1e-12);
      total += s.total_volume;
      ++sections_seen;
    }
    EXPECT_NEAR(frame->total_volume, total, 1e-12 + 1e-12 * total);
    // every object without a section is apart from the tool by brute force
    for (std::size_t i = 0; i < room.ids.size(); ++i)
      if (in_frame.count(room.ids[i]) == 0) {
        EXPECT_EQ(brute_force_volume(small_leaves, room.poses[i], leaves, tool_pose), 0.0);
      }
  }
  EXPECT_GT(sections_seen, 20) << "the path must touch objects";
  const CollisionWorldStats stats = world.stats();
  EXPECT_LT(stats.broad_phase_candidates, 30u * 40u / 2) << "the broad phase must skip most objects";
}

TEST_F(WorldFixture, ObjectsComeAndGoWhileTheThreadRunsAndTheReaderTakesFrames) {
  CollisionWorld world(
      {.rate_hz = 4000.0, .compute_distance = false, .max_objects = 64, .max_pending_changes = 16});
  const auto small = make_tree(lattice_block(2, 0.05f));
  const ObjectId tool = *world.add_object({.tree = tree, .world_from_object = Pose{}, .name = "tool"});
  const WatcherId w = *world.add_tool_watcher(tool);
  ASSERT_TRUE(world.start().has_value());
  std::atomic<bool> done{false};
  std::atomic<int> frames{0}, sections{0}, bad{0};
  std::thread reader([&] {
    while (!done.load()) {
      if (const ContactFrame* f = world.take_contact(w)) {
        ++frames;
        double total = 0.0;
        for (const ContactSection& s : f->sections()) {
          ++sections;
          total += s.total_volume;
          if (s.first_pair + s.pair_count > f->pair_count || s.object_b != tool) ++bad;
        }
        if (std::abs(total - f->total_volume) > 1e-9 * (1.0 + total)) ++bad;
      }
      std::this_thread::sleep_for(std::chrono::microseconds(100));
    }
  });
  // this thread adds objects in and out of the tool, removes them again, and moves some meanwhile
  std::vector<ObjectId> live;
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> coord(-0.5, 0.5);
  for (int round = 0; round < 200; ++round) {
    const auto added = world.add_object(
        {.tree = small, .world_from_object = {{}, {coord(rng), coord(rng), coord(rng)}}, .name = "o"});
    if (added) live.push_back(*added);  // refusals (too many waiting changes) are fine: retried next round
    if (live.size() > 20 || (round % 3 == 0 && !live.empty())) {
      const ObjectId gone = live.front();
      if (world.remove_object(gone).has_value()) {
        live.erase(live.begin());
        EXPECT_FALSE(world.set_pose(gone, Pose{}));
      }
    }
    if (!live.empty()) world.set_pose(live.back(), Pose{{}, {coord(rng), 0.0, 0.0}});
    std::this_thread::sleep_for(std::chrono::microseconds(300));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  done = true;
  reader.join();
  world.stop();
  EXPECT_EQ(bad.load(), 0);
  EXPECT_GT(frames.load(), 10);
  EXPECT_GT(sections.load(), 0);
  EXPECT_EQ(world.stats().objects, static_cast<std::int32_t>(live.size()) + 1);
}

TEST_F(WorldFixture, FrameMemoryFollowsTheOverlap) {
  CollisionWorld world({.compute_distance = false});
  const auto fine = make_tree(lattice_block(12, 0.025f));  // the same cube, 1,728 spheres
  const ObjectId a = *world.add_object({.tree = fine, .name = "a"});
  const ObjectId b =
      *world.add_object({.tree = fine, .world_from_object = {{}, {0.0125, 0.0125, 0.0125}}, .name = "b"});
  const WatcherId w = *world.add_collision_watcher(a, b);
  for (int i = 0; i < 3; ++i) {  // deep: every slot of the handoff holds the deep frame once
    world.step(0.001 * i);
    ASSERT_NE(world.take_contact(w), nullptr);
  }
  const std::int64_t deep = world.stats().frame_bytes;
  const std::int64_t pairs = world.stats().last_pairs;
  ASSERT_GT(pairs, 3000);
  EXPECT_GE(deep, 3 * pairs * static_cast<std::int64_t>(sizeof(SpherePairContact)));
  EXPECT_LE(deep, 3 * 2 * pairs * static_cast<std::int64_t>(sizeof(SpherePairContact)) + 4096);
  ASSERT_TRUE(world.set_pose(b, Pose{{}, {0.58, 0, 0}}));  // a graze: a few pairs
  for (int i = 3; i < 9; ++i) {
    world.step(0.001 * i);
    ASSERT_NE(world.take_contact(w), nullptr);
  }
  const std::int64_t graze_pairs = world.stats().last_pairs;
  ASSERT_GT(graze_pairs, 0);
  ASSERT_LT(graze_pairs, pairs / 10);
  EXPECT_LT(world.stats().frame_bytes, deep / 4) << "the frames give back what the deep contact took";
}

}  // namespace
}  // namespace uh::collette
