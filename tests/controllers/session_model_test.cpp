#include "uh/controllers/session_model.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <sstream>

#include <nlohmann/json.hpp>

#include "scene_test_support.hpp"
#include "uh/collette/sphere_tree_builder.hpp"
#include "uh/controllers/haptic_session.hpp"
#include "uh/haptico/device_registry.hpp"
#include "uh/haptico/sim_line_device.hpp"

namespace uh::controllers {
namespace {

using testing::small_scene_json;
using testing::test_assets;

Scene small_scene() {
  auto scene = parse_scene(small_scene_json(), "small.json", test_assets());
  EXPECT_TRUE(scene.has_value()) << scene.error().message;
  return *scene;
}

TEST(SessionModel, OneModelServesTwoSessionsWithOneTree) {
  collette::IstCache cache(testing::fresh_cache("model-two"));
  auto model = compile(small_scene(), cache);
  ASSERT_TRUE(model.has_value()) << model.error().message;
  ASSERT_EQ((*model)->objects.size(), 1u);
  ASSERT_EQ((*model)->tools.size(), 1u);
  EXPECT_NE((*model)->objects[0].surface, nullptr) << "the bunny has a mesh file";
  ASSERT_EQ((*model)->materials.size(), 1u);
  ASSERT_EQ((*model)->materials[0].size(), 1u);

  auto first = HapticSession::create(*model);
  auto second = HapticSession::create(*model);
  ASSERT_TRUE(first.has_value()) << first.error().message;
  ASSERT_TRUE(second.has_value()) << second.error().message;
  EXPECT_EQ(&(*first)->model(), &(*second)->model());
  EXPECT_EQ((*first)->model().objects[0].tree.get(), (*model)->objects[0].tree.get());
  EXPECT_EQ((*second)->model().objects[0].tree.get(), (*model)->objects[0].tree.get());

  // both run as a session created from the scene does, bit for bit
  std::ostringstream trace_a, trace_b;
  ASSERT_TRUE((*first)->run_stepped(0.5, 4, &trace_a).has_value());
  ASSERT_TRUE((*second)->run_stepped(0.5, 4, &trace_b).has_value());
  EXPECT_GT((*first)->report().contact_ticks, 0u);
  EXPECT_EQ(trace_a.str(), trace_b.str());
  SessionOptions options;
  options.cache_dir = cache.dir();
  auto from_scene = HapticSession::create(small_scene(), options);
  ASSERT_TRUE(from_scene.has_value()) << from_scene.error().message;
  std::ostringstream trace_c;
  ASSERT_TRUE((*from_scene)->run_stepped(0.5, 4, &trace_c).has_value());
  EXPECT_EQ(trace_a.str(), trace_c.str());

  // a second compile through the same cache shares the trees as well
  auto again = compile(small_scene(), cache);
  ASSERT_TRUE(again.has_value());
  EXPECT_EQ((*again)->objects[0].tree.get(), (*model)->objects[0].tree.get());
  EXPECT_EQ((*again)->tools[0].tree.get(), (*model)->tools[0].tree.get());
}

// A device the caller made drives its tool as the registry's would: the small scene's sim-line
// built by hand gives the registry-made session's trace bit for bit, through a registry that knows
// no driver at all (which alone cannot open the scene's); more devices than tools are refused.
TEST(SessionModel, ADeviceTheCallerMadeDrivesItsTool) {
  collette::IstCache cache(testing::fresh_cache("model-device"));
  auto model = compile(small_scene(), cache);
  ASSERT_TRUE(model.has_value()) << model.error().message;
  const haptico::DeviceRegistry none;
  const auto hand = [] {
    std::vector<std::unique_ptr<haptico::HapticDevice>> devices;
    devices.push_back(std::make_unique<haptico::SimLineDevice>(haptico::SimLineOptions{
        .device = {.rate_hz = 1000.0, .max_force_n = 6.0, .dof_actuated = 6},
        .start = {0.0, 0.0, 0.10},
        .end = {0.0, 0.0, 0.045},
        .duration_s = 0.5,
        .bounce = true}));
    return devices;
  };
  auto given = HapticSession::create(*model, hand(), {}, none);
  ASSERT_TRUE(given.has_value()) << given.error().message;
  auto made = HapticSession::create(*model);
  ASSERT_TRUE(made.has_value()) << made.error().message;
  std::ostringstream trace_given, trace_made;
  ASSERT_TRUE((*given)->run_stepped(0.5, 4, &trace_given).has_value());
  ASSERT_TRUE((*made)->run_stepped(0.5, 4, &trace_made).has_value());
  EXPECT_GT((*given)->report().contact_ticks, 0u);
  EXPECT_EQ(trace_given.str(), trace_made.str());

  const auto unknown = HapticSession::create(*model, {}, none);
  ASSERT_FALSE(unknown.has_value()) << "the empty registry cannot open sim-line";
  auto two = hand();
  two.push_back(std::move(hand().front()));
  const auto too_many = HapticSession::create(*model, std::move(two), {}, none);
  ASSERT_FALSE(too_many.has_value());
  EXPECT_NE(too_many.error().message.find("2 devices given for 1 tool(s)"), std::string::npos)
      << too_many.error().message;
}

TEST(SessionModel, ATreeGivenForTheToolOrTheObjectKeepsTheObjectsMeshSurface) {
  collette::IstCache cache(testing::fresh_cache("model-tree"));
  Scene scene = small_scene();
  const Sphere ball{0.f, 0.f, 0.f, 0.004f};
  auto tip = collette::build_sphere_tree(std::span<const Sphere>(&ball, 1));
  ASSERT_TRUE(tip.has_value());
  scene.tool().shape.tree = std::make_shared<const collette::SphereTree>(std::move(*tip));
  auto model = compile(scene, cache);
  ASSERT_TRUE(model.has_value()) << model.error().message;
  EXPECT_EQ((*model)->tools[0].tree.get(), scene.tool().shape.tree.get()) << "a tree given is used as it is";
  ASSERT_NE((*model)->objects[0].surface, nullptr);

  // a program that preloads the object's tree beside its mesh still gets the surface
  scene.objects[0].shape.tree = (*model)->objects[0].tree;
  scene.objects[0].shape.coverage = (*model)->objects[0].coverage;
  auto preloaded = compile(scene, cache);
  ASSERT_TRUE(preloaded.has_value()) << preloaded.error().message;
  EXPECT_EQ((*preloaded)->objects[0].tree.get(), (*model)->objects[0].tree.get());
  ASSERT_NE((*preloaded)->objects[0].surface, nullptr);
  EXPECT_EQ((*preloaded)->objects[0].surface->distance(Vec3{0.0, 0.0, 0.1}),
            (*model)->objects[0].surface->distance(Vec3{0.0, 0.0, 0.1}));
}

// A tree in memory alone (no mesh file: the C API's and Python's trees, loaded from a .ist or built
// from arrays) gives the proxy the surface it carries, with its packing's gap; without one, none.
TEST(SessionModel, ATreeInMemoryAloneBringsItsSurface) {
  collette::IstCache cache(testing::fresh_cache("model-memory"));
  Scene scene = small_scene();
  auto model = compile(scene, cache);
  ASSERT_TRUE(model.has_value()) << model.error().message;
  const CompiledShape& bunny = (*model)->objects[0];
  ASSERT_NE(bunny.surface, nullptr);
  scene.objects[0].shape = {.tree = bunny.tree, .coverage = bunny.coverage, .surface = bunny.surface,
                            .surface_gap_m = bunny.surface_gap_m};
  auto alone = compile(scene, cache);
  ASSERT_TRUE(alone.has_value()) << alone.error().message;
  EXPECT_EQ((*alone)->objects[0].surface.get(), bunny.surface.get());
  EXPECT_EQ((*alone)->objects[0].surface_gap_m, bunny.surface_gap_m);
  EXPECT_GT(bunny.surface_gap_m, 0.0);
  scene.objects[0].shape.surface = nullptr;
  auto bare = compile(scene, cache);
  ASSERT_TRUE(bare.has_value()) << bare.error().message;
  EXPECT_EQ((*bare)->objects[0].surface, nullptr) << "a tree without a surface rests the proxy on its spheres";
}

TEST(SessionModel, CompileRefusesAnInvalidSceneNamingTheField) {
  collette::IstCache cache(testing::fresh_cache("model-invalid"));
  Scene scene = small_scene();
  scene.objects[0].shape.spheres = 0;
  auto model = compile(scene, cache);
  ASSERT_FALSE(model.has_value());
  EXPECT_EQ(model.error().message,
            "small.json: field 'objects[0].spheres': expected a whole number in [1, 2000000], got 0");
}

// a 7 x 7 x 2 cm block (top face at z = 0), soft, its base held
Scene soft_block_scene(const std::string& fixed_box) {
  auto json = nlohmann::json::parse(small_scene_json());
  json["objects"][0] = nlohmann::json::parse(R"({"name": "block", "mesh": "meshes/block.obj", "meters_per_unit": 0.01,
      "spheres": 600, "deformable": {"young_modulus_pa": 3e4, "poisson_ratio": 0.4}})");
  if (!fixed_box.empty()) json["objects"][0]["deformable"]["fixed"] = nlohmann::json::parse(fixed_box);
  json["watch"] = {"block"};
  auto scene = parse_scene(json.dump(), "soft.json", test_assets());
  EXPECT_TRUE(scene.has_value()) << scene.error().message;
  return *scene;
}

TEST(SessionModel, ADeformableObjectCarriesItsLatticeAndEmbeddedPacking) {
  collette::IstCache cache(testing::fresh_cache("model-soft"));
  std::vector<std::string> stages;
  CompileOptions options;
  options.surfaces = false;  // the lattice loads the surface it needs itself
  options.progress = [&](const std::string& what, double) { stages.push_back(what); };
  auto model = compile(soft_block_scene(R"({"box": [[-1, -1, -1], [1, 1, -0.0195]]})"), cache, options);
  ASSERT_TRUE(model.has_value()) << model.error().message;
  const CompiledShape& block = (*model)->objects[0];
  ASSERT_NE(block.soft, nullptr);
  EXPECT_EQ((*model)->tools[0].soft, nullptr);
  const soft::SoftBodyModel& body = *block.soft;
  // the default size: cells of a tenth of 7 cm over the 7 x 7 x 2 cm packing
  const auto tets = static_cast<int>(body.mesh.tets.size());
  EXPECT_GE(tets, 384);
  EXPECT_LE(tets, 3000 * 11 / 10);
  EXPECT_EQ(body.spheres.size(), block.tree->leaves().size());
  ASSERT_FALSE(body.fixed.empty());
  for (std::int32_t n : body.fixed) EXPECT_LE(body.mesh.nodes[static_cast<std::size_t>(n)].z(), -0.0195);
  EXPECT_EQ(body.material.young_modulus_pa, 3e4);
  EXPECT_NE(std::find(stages.begin(), stages.end(), "meshing the volume of 'block'"), stages.end());

  // a box above the block holds nothing: refused, naming the object
  auto refused = compile(soft_block_scene(R"({"box": [[-1, -1, 0.01], [1, 1, 0.02]]})"), cache);
  ASSERT_FALSE(refused.has_value());
  EXPECT_NE(refused.error().message.find("object 'block': soft::build_soft_body: the fixed box holds no node"),
            std::string::npos)
      << refused.error().message;
}

}  // namespace
}  // namespace uh::controllers
