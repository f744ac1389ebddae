// A soft object's tree under a large deformation (issue 26: "refitted bottom-up each step, rebuilt
// only when too distorted"): a 7 x 7 x 2 cm block of 1,500 spheres, its base held, its top layer
// of spheres pushed sideways (sheared until the top has moved about its height), stepped by SoftSimulation
// and read back as the collision thread reads it (the triple buffer):
// - every published tree passes collette::validate;
// - a step rebuilds the tree, and from then on every published tree has the rebuilt hierarchy
//   (each slot of the triple buffer got it, none refitted an older one);
// - the rebuilt tree's looseness (leaf-parent sphere volume over the object's volume) is back
//   near the rest tree's, where the rest tree refitted to the same spheres stays far above;
// - a volume query against the published tree finds the pairs and volume of a brute-force loop
//   over all leaf pairs;
// - the same with the rebuilds on a worker thread;
// - a proxy's haptic thread feels the compliance of the step whose tree the collision thread took,
//   not the newest step's.
// Also under ThreadSanitizer (label "threads").

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <set>
#include <thread>
#include <utility>
#include <vector>

#include "../collette/tree_test_support.hpp"
#include "uh/collette/sphere_tree_builder.hpp"
#include "uh/collette/volume_query.hpp"
#include "uh/controllers/soft_simulation.hpp"
#include "uh/soft/soft_body.hpp"

namespace uh::controllers {
namespace {

const Eigen::Vector3d kMin(-0.035, -0.035, -0.02), kMax(0.035, 0.035, 0.0);  // [m]
constexpr double kSpacing = 0.0035;                                          // [m]

std::vector<Sphere> block_packing() {
  std::vector<Sphere> leaves;
  for (double z = kMin.z() + 0.5 * kSpacing; z < kMax.z(); z += kSpacing)
    for (double y = kMin.y() + 0.5 * kSpacing; y < kMax.y(); y += kSpacing)
      for (double x = kMin.x() + 0.5 * kSpacing; x < kMax.x(); x += kSpacing)
        leaves.push_back({static_cast<float>(x), static_cast<float>(y), static_cast<float>(z),
                          static_cast<float>(0.45 * kSpacing)});
  return leaves;
}

struct Block {
  std::vector<Sphere> leaves;
  std::shared_ptr<const soft::SoftBodyModel> body;
  std::shared_ptr<const collette::SphereTree> tree;
};

Block make_block() {
  Block b;
  b.leaves = block_packing();
  soft::SoftBodyParams params{.material = {.young_modulus_pa = 5.0e4,
                                           .poisson_ratio = 0.4,
                                           .density_kg_m3 = 1000.0,
                                           .stiffness_damping_s = 0.02},
                              .target_tetrahedra = 1500,
                              .fixed = soft::Box{.min = kMin - Eigen::Vector3d::Constant(0.01),
                                                 .max = Eigen::Vector3d(0.05, 0.05, kMin.z() + 1e-3)}};
  auto body = soft::build_soft_body([](const Eigen::Vector3d&) { return true; }, b.leaves, params);
  EXPECT_TRUE(body) << body.error().message;
  auto tree = collette::build_sphere_tree(b.leaves);
  EXPECT_TRUE(tree) << tree.error().message;
  b.body = std::make_shared<const soft::SoftBodyModel>(std::move(body).value());
  b.tree = std::make_shared<const collette::SphereTree>(std::move(tree).value());
  return b;
}

// the leaf index or child range of each node: what a hierarchy is, apart from where it lies
std::vector<std::int64_t> hierarchy_of(const collette::SphereTree& tree) {
  std::vector<std::int64_t> out;
  for (const collette::SphereTreeNode& n : tree.nodes())
    out.push_back((std::int64_t{n.first} << 8) | n.count);
  return out;
}

double looseness(const collette::SphereTree& tree, const soft::SoftBodyModel& body,
                 const std::vector<Eigen::Vector3d>& x) {
  return tree.leaf_parent_volume() / soft::mesh_volume(body.mesh, x);
}

struct Pushed {
  std::uint64_t rebuilds = 0;
  double largest_distortion = 0.0;
  double top_moved_m = 0.0;  // the top layer's mean move
  int first_rebuild_step = -1;
};

// `load_n` [N, object frame] on the top layer's spheres for `steps` steps of 10 ms, `pause_s` of wall
// time after each; checks each published tree as the collision thread reads it
Pushed push(const Block& b, SoftSimulation& sim, const Eigen::Vector3d& load_n, int steps, double pause_s = 0.0) {
  std::vector<std::int32_t> top;
  for (std::size_t i = 0; i < b.leaves.size(); ++i)
    if (b.leaves[i].z > static_cast<float>(kMax.z() - kSpacing)) top.push_back(static_cast<std::int32_t>(i));
  ContactFrame frame;
  frame.object_a = 0;
  frame.resize_pairs(static_cast<std::int32_t>(top.size()));
  for (std::size_t k = 0; k < top.size(); ++k) {
    frame.pairs()[k].leaf_a = top[k];
    frame.pairs()[k].volume = 1.f;
  }
  sim.post_contacts(0, 0, frame);

  Pushed out;
  std::vector<std::int64_t> expected = hierarchy_of(*b.tree);
  for (int step = 0; step < steps; ++step) {
    // ramped up over the first half, so that the block does not overshoot; the block takes minus
    // what the tool felt
    const Eigen::Vector3d load = load_n * std::min(1.0, 2.0 * (step + 1) / steps);
    sim.post_tool_force(0, Vec3{-load.x(), -load.y(), -load.z()});
    EXPECT_TRUE(sim.step(0.01)) << "step " << step;
    if (pause_s > 0.0) std::this_thread::sleep_for(std::chrono::duration<double>(pause_s));
    out.largest_distortion = std::max(out.largest_distortion, sim.tree_distortion());
    EXPECT_TRUE(sim.trees().update());
    const collette::SphereTree& published = sim.trees().read_buffer();
    const Status valid = collette::validate(published);
    EXPECT_TRUE(valid) << "step " << step << ": " << valid.error().message;
    if (sim.tree_rebuilds() != out.rebuilds) {
      out.rebuilds = sim.tree_rebuilds();
      if (out.first_rebuild_step < 0) out.first_rebuild_step = step;
      EXPECT_NE(hierarchy_of(published), expected) << "step " << step << " rebuilt to the same hierarchy";
      expected = hierarchy_of(published);
    }
    EXPECT_EQ(hierarchy_of(published), expected) << "step " << step << ": a slot kept an older hierarchy";
  }
  double moved = 0.0;
  for (std::int32_t leaf : top) {
    const Sphere& s = sim.spheres()[static_cast<std::size_t>(leaf)];
    const Sphere& r = b.leaves[static_cast<std::size_t>(leaf)];
    moved += std::hypot(double{s.x} - double{r.x}, double{s.y} - double{r.y}, double{s.z} - double{r.z});
  }
  out.top_moved_m = moved / static_cast<double>(top.size());
  return out;
}

// the published tree against the refit-only tree and brute force, after a large deformation
void expect_rebuilt_tree_is_tight_and_exact(const Block& b, SoftSimulation& sim) {
  const collette::SphereTree& published = sim.trees().read_buffer();
  const std::vector<Eigen::Vector3d>& x = sim.fem().positions();
  collette::SphereTree refit_only = *b.tree;
  refit_only.refit(sim.spheres());
  collette::SphereTree rest_refitted = *b.tree;  // the refit's spheres, as the published trees have
  rest_refitted.refit(b.leaves);
  const double rest = looseness(rest_refitted, *b.body, b.body->mesh.nodes);
  std::printf("looseness over the rest tree's: refit only %.3f, published %.3f\n",
              looseness(refit_only, *b.body, x) / rest, looseness(published, *b.body, x) / rest);
  EXPECT_GT(looseness(refit_only, *b.body, x), SoftTreeOptions::kRebuildDistortion * rest);
  EXPECT_LT(looseness(published, *b.body, x), 1.15 * rest);
  EXPECT_LT(sim.tree_distortion(), SoftTreeOptions::kRebuildDistortion);

  // a 1 cm ball of spheres pressed into the top, brute force over all leaf pairs
  const std::vector<Sphere> ball = collette::testing::make_packing(0.15, collette::testing::Shape::kBall, 3);
  std::vector<Sphere> small;
  for (const Sphere& s : ball) small.push_back({0.01f * s.x, 0.01f * s.y, 0.01f * s.z, 0.01f * s.radius});
  auto ball_tree = collette::build_sphere_tree(small);
  ASSERT_TRUE(ball_tree);
  const std::vector<Sphere> leaves(sim.spheres().begin(), sim.spheres().end());
  collette::VolumeQuery query;
  int touching = 0;
  for (const Vec3 at : {Vec3{0.0, 0.0, 0.0}, Vec3{0.02, 0.01, -0.005}, Vec3{-0.015, 0.02, -0.01}}) {
    const Pose pose{Quat{}, at + Vec3{double{leaves[0].x} - double{b.leaves[0].x}, 0.0, 0.0}};
    const collette::testing::BruteVolume ref = collette::testing::brute_volume(leaves, small, pose);
    const collette::VolumeQueryResult& r = query.run(published, *ball_tree, pose);
    EXPECT_NEAR(r.total_volume, ref.volume, 1e-4 * ref.volume + 1e-15);
    std::set<std::pair<int, int>> got;
    for (const collette::PairOverlap& p : query.pairs()) got.emplace(p.leaf_a, p.leaf_b);
    EXPECT_EQ(got, (std::set<std::pair<int, int>>(ref.pairs.begin(), ref.pairs.end())));
    touching += ref.pairs.empty() ? 0 : 1;
  }
  EXPECT_GE(touching, 2);
}

TEST(SoftTreeRebuild, AShearedBlockRebuildsItsTreeIntoEverySlot) {
  const Block b = make_block();
  auto sim = SoftSimulation::create(b.body, b.tree, Pose{}, 1);
  ASSERT_TRUE(sim) << sim.error().message;
  const Pushed p = push(b, **sim, Eigen::Vector3d(90.0, 0.0, 0.0), 150);
  std::printf("sheared: top moved %.1f mm, %llu rebuilds (the first at step %d), largest distortion %.2f\n",
              1e3 * p.top_moved_m, static_cast<unsigned long long>(p.rebuilds), p.first_rebuild_step,
              p.largest_distortion);
  EXPECT_GT(p.top_moved_m, 0.015);
  EXPECT_GE(p.rebuilds, 1u);
  expect_rebuilt_tree_is_tight_and_exact(b, **sim);
}

// The same with the rebuilds on a worker thread (as a session's simulation thread runs them): the
// steps go on refitting the older hierarchy meanwhile, and every slot takes the rebuilt one.
TEST(SoftTreeRebuild, RebuiltOnAWorkerTheShearedBlocksTreeReachesEverySlot) {
  const Block b = make_block();
  auto sim = SoftSimulation::create(b.body, b.tree, Pose{}, 1);
  ASSERT_TRUE(sim) << sim.error().message;
  (*sim)->work_in_background(true);
  // a simulation thread's pace at 200 Hz, so that the worker's rebuilds arrive between steps
  const Pushed p = push(b, **sim, Eigen::Vector3d(90.0, 0.0, 0.0), 150, 0.005);
  std::printf("sheared, rebuilt on the worker: top moved %.1f mm, %llu rebuilds (the first taken at step %d), "
              "largest distortion %.2f\n",
              1e3 * p.top_moved_m, static_cast<unsigned long long>(p.rebuilds), p.first_rebuild_step,
              p.largest_distortion);
  EXPECT_GE(p.rebuilds, 1u);
  (*sim)->work_in_background(false);
  expect_rebuilt_tree_is_tight_and_exact(b, **sim);
}

TEST(SoftTreeRebuild, WithoutRebuildsTheSameShearOnlyRefits) {
  const Block b = make_block();
  auto sim = SoftSimulation::create(b.body, b.tree, Pose{}, 1,
                                    {.rebuild_distortion = std::numeric_limits<double>::infinity()});
  ASSERT_TRUE(sim) << sim.error().message;
  const Pushed p = push(b, **sim, Eigen::Vector3d(90.0, 0.0, 0.0), 150);
  EXPECT_EQ(p.rebuilds, 0u);
  EXPECT_GT(p.largest_distortion, SoftTreeOptions::kRebuildDistortion);
  EXPECT_FALSE(SoftSimulation::create(b.body, b.tree, Pose{}, 1, {.rebuild_distortion = 1.0}));
}

// A proxy rests on the tree the collision step took, so the compliance its haptic thread feels
// (SoftSimulation::compliance: how that surface will give) must be of the step that published that
// tree: the newest step's describes a surface the proxy does not rest on yet (it made the force
// step up at the simulation step and back at the collision step, docs/deformables.md). A tool
// sphere rests on the top layer's middle sphere; the simulation steps twice, then the collision
// thread takes the newest tree, then the simulation steps again.
TEST(SoftTreeRebuild, AProxyFeelsTheComplianceOfTheTreeItRestsOn) {
  const Block b = make_block();
  auto made = SoftSimulation::create(b.body, b.tree, Pose{}, 1);
  ASSERT_TRUE(made) << made.error().message;
  SoftSimulation& sim = **made;
  sim.rest_on_proxy(0, 2e-4);
  std::size_t middle = 0;
  const auto off_middle = [](const Sphere& s) { return std::abs(s.x) + std::abs(s.y) - s.z; };
  for (std::size_t i = 0; i < b.leaves.size(); ++i)
    if (off_middle(b.leaves[i]) < off_middle(b.leaves[middle])) middle = i;
  const Sphere& under = b.leaves[middle];
  const Sphere tool_sphere{0.f, 0.f, 0.f, 0.005f};
  const auto d = [](float x) { return static_cast<double>(x); };
  const Pose tool{.rotation = {},
                  .position = {d(under.x), d(under.y), d(under.z) + d(under.radius) + d(tool_sphere.radius) + 1e-5}};
  ContactFrame frame;
  frame.object_a = 0;
  frame.object_b = 1;
  frame.resize_pairs(1);
  frame.pairs()[0].leaf_a = static_cast<std::int32_t>(middle);
  frame.pairs()[0].sphere_a_local = under;
  frame.pairs()[0].sphere_b_local = tool_sphere;
  frame.add_section({.object_a = 0, .object_b = 1, .world_from_a = {}, .world_from_b = tool, .pair_count = 1});
  sim.post_contacts(0, 0, frame);
  sim.rest_proxy_at(0, tool);
  EXPECT_FALSE(sim.compliance(0).update()) << "no step yet: the rest tree";
  sim.post_tool_force(0, Vec3{0.0, 0.0, 1.0});  // the block pushes the tool up: it takes 1 N down
  ASSERT_TRUE(sim.step(0.005));
  ASSERT_TRUE(sim.step(0.005));
  sim.rest_proxy_at(0, tool);
  EXPECT_FALSE(sim.compliance(0).update()) << "the collision thread has taken no step's tree yet";
  ASSERT_TRUE(sim.trees().update());  // the collision thread takes the newest tree, step 2's
  sim.rest_proxy_at(0, tool);
  ASSERT_TRUE(sim.compliance(0).update());
  EXPECT_EQ(sim.compliance(0).read_buffer().step, 2u);
  EXPECT_GT(sim.compliance(0).read_buffer().compliance_m_per_n, 0.0);
  EXPECT_NEAR(sim.compliance(0).read_buffer().force_world.z, 1.0, 1e-12);
  ASSERT_TRUE(sim.step(0.005));
  sim.rest_proxy_at(0, tool);
  EXPECT_FALSE(sim.compliance(0).update()) << "the proxy still rests on step 2's tree";
  ASSERT_TRUE(sim.trees().update());
  sim.rest_proxy_at(0, tool);
  ASSERT_TRUE(sim.compliance(0).update());
  EXPECT_EQ(sim.compliance(0).read_buffer().step, 3u);
}

}  // namespace
}  // namespace uh::controllers
