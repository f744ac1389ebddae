#include "uh/controllers/scene.hpp"

#include <gtest/gtest.h>

#include <sys/stat.h>

#include <algorithm>
#include <fstream>
#include <set>

#include "scene_test_support.hpp"
#include "uh/collette/ist_file.hpp"

namespace uh::controllers {
namespace {

using testing::replaced;
using testing::small_scene_json;
using testing::test_assets;

Result<Scene> parse(const std::string& text) { return parse_scene(text, "test.json", test_assets() / "scenes"); }

void expect_error(const std::string& text, const std::string& needle) {
  const auto scene = parse(text);
  ASSERT_FALSE(scene.has_value()) << "expected an error containing: " << needle;
  EXPECT_NE(scene.error().message.find(needle), std::string::npos) << scene.error().message;
  EXPECT_EQ(scene.error().message.rfind("test.json", 0), 0u) << "errors start with the file name: " << scene.error().message;
}

TEST(Scene, ParsesTheSmallTestScene) {
  const auto scene = parse_scene(small_scene_json(), "small.json", test_assets());
  ASSERT_TRUE(scene.has_value()) << scene.error().message;
  ASSERT_EQ(scene->objects.size(), 1u);
  EXPECT_EQ(scene->objects[0].name, "bunny");
  EXPECT_EQ(scene->objects[0].shape.spheres, 600);
  EXPECT_DOUBLE_EQ(scene->objects[0].shape.meters_per_unit, 0.01);
  EXPECT_NEAR(scene->objects[0].pose.rotation.x, std::sqrt(0.5), 1e-6);
  EXPECT_EQ(scene->tool().device.driver, "sim-line");
  EXPECT_EQ(scene->tool().device.config.text("end", ""), "0,0,0.045");
  EXPECT_EQ(scene->tool().force.law, forcecomp::ForceLaw::kGradient) << "the gradient law is the default";
  EXPECT_DOUBLE_EQ(scene->tool().force.stiffness, 1.6e4);
  EXPECT_EQ(scene->watch, std::vector<std::string>{"bunny"});
  EXPECT_TRUE(scene->force.multi_rate);
  EXPECT_DOUBLE_EQ(scene->coherence_skin, 0.0) << "coherence is off unless a scene asks for it";
}

TEST(Scene, ReadsThePaperLawWithItsForceScale) {
  const auto scene =
      parse_scene(replaced(replaced(small_scene_json(), R"("stiffness": 1.6e4)", R"("force_scale": 8.0e6)"),
                           R"("mode": "6dof")", R"("mode": "6dof", "law": "paper")"),
                  "small.json", test_assets());
  ASSERT_TRUE(scene.has_value()) << scene.error().message;
  EXPECT_EQ(scene->tool().force.law, forcecomp::ForceLaw::kPaper);
  EXPECT_DOUBLE_EQ(scene->tool().force.force_scale, 8.0e6);
}

TEST(Scene, ReadsTheCollisionSection) {
  const std::string with_collision =
      replaced(small_scene_json(), R"("rates":)", R"("collision": { "contact_margin": 0.002, "coherence_skin": 0.0005 }, "rates":)");
  const auto scene = parse_scene(with_collision, "small.json", test_assets());
  ASSERT_TRUE(scene.has_value()) << scene.error().message;
  EXPECT_DOUBLE_EQ(scene->contact_margin, 0.002);
  EXPECT_DOUBLE_EQ(scene->coherence_skin, 0.0005);
  const auto bad = parse_scene(replaced(with_collision, "0.0005", "-1"), "small.json", test_assets());
  ASSERT_FALSE(bad.has_value());
  EXPECT_NE(bad.error().message.find("field 'collision.coherence_skin': expected a number in [0, 1]"), std::string::npos)
      << bad.error().message;
}

TEST(Scene, ReportsFileFieldAndExpectation) {
  const std::string good = small_scene_json();
  // the test scene's paths are relative to assets/, so parse() (base assets/scenes) must not find them
  expect_error(good, "field 'objects[0].mesh': file not found");
  const auto base = test_assets();
  const auto with_base = [&](const std::string& text, const std::string& needle) {
    const auto scene = parse_scene(text, "test.json", base);
    ASSERT_FALSE(scene.has_value()) << needle;
    EXPECT_NE(scene.error().message.find(needle), std::string::npos) << scene.error().message;
  };
  with_base(replaced(good, R"("haptic_hz": 1000)", R"("haptic_hz": "fast")"), "field 'rates.haptic_hz': expected a number");
  with_base(replaced(good, R"("haptic_hz": 1000)", R"("haptic_hz": 50000)"), "field 'rates.haptic_hz': expected a number in [1, 10000]");
  with_base(replaced(good, R"("spheres": 600)", R"("sphers": 600)"), "field 'objects[0].sphers': unknown field");
  with_base(replaced(good, R"("spheres": 600)", R"("spheres": 2.5)"), "field 'objects[0].spheres': expected a whole number");
  with_base(replaced(good, R"("spheres": 600)", R"("spheres": 600, "max_sphere_radius": -0.001)"),
            "field 'objects[0].max_sphere_radius': expected a number in [1e-09, 1000000], got -0.001");
  with_base(replaced(good, R"("spheres": 600)", R"("spheres": 600, "max_sphere_radius": "small")"),
            "field 'objects[0].max_sphere_radius': expected a number, got string");
  with_base(replaced(good, R"("mesh": "meshes/stylus.obj",)",
                     R"("ist": "meshes/stylus.obj", "max_sphere_radius": 0.001,)"),
            "field 'tool.max_sphere_radius': applies only when packing a 'mesh'");
  with_base(replaced(good, R"("name": "bunny",)", ""), "field 'objects[0].name': missing");
  with_base(replaced(good, R"("rotation": [0.70710678, 0.70710678, 0, 0])", R"("rotation": [0, 0, 0, 0])"),
            "field 'objects[0].pose.rotation': expected a non-zero quaternion");
  with_base(replaced(good, R"("mode": "6dof")", R"("mode": "7dof")"), "field 'tool.force.mode': expected \"3dof\" or \"6dof\"");
  with_base(replaced(good, R"("mode": "6dof")", R"("mode": "6dof", "law": "volume")"),
            "field 'tool.force.law': expected \"gradient\" or \"paper\", got \"volume\"");
  // a stiffness meant for the other law is refused, not ignored (its unit differs)
  with_base(
      replaced(good, R"("stiffness": 1.6e4)", R"("force_scale": 8.0e6)"),
      "field 'tool.force.force_scale': is the paper law's stiffness [N/m^3]; the gradient law (the default) "
      "takes 'stiffness' [N/m^2]");
  with_base(replaced(good, R"("mode": "6dof")", R"("mode": "6dof", "law": "paper")"),
            "field 'tool.force.stiffness': is the gradient law's stiffness [N/m^2]; the paper law takes "
            "'force_scale'");
  with_base(replaced(good, R"("stiffness": 1.6e4)", R"("stiffness": -1)"),
            "field 'tool.force.stiffness': expected a number in [0,");
  with_base(replaced(good, R"("watch": ["bunny"])", R"("watch": ["dragon"])"), "field 'watch[0]': no object is named 'dragon'");
  with_base(replaced(good, R"("driver": "sim-line",)", R"("driver": 7,)"), "field 'tool.device.driver': expected a non-empty string");
  with_base(replaced(good, R"("mesh": "meshes/stylus.obj",)", R"("mesh": "meshes/stylus.obj", "ist": "x.ist",)"),
            "field 'tool': give exactly one of 'mesh'");
  with_base("[1, 2]", "expected a JSON object at the top level");
  with_base("{ \"objects\": ", "not valid JSON");
  with_base(R"({ "seconds": 1e999 })", "not valid JSON");  // a number no double holds (the fuzzer's first find)
  with_base(R"({ "tool": {} })", "field 'objects': missing");
}

TEST(Scene, ReadsHowTheTickComputesTheForce) {
  const auto defaults = parse_scene(small_scene_json(), "small.json", test_assets());
  ASSERT_TRUE(defaults.has_value()) << defaults.error().message;
  EXPECT_EQ(defaults->force.tick_force, TickForce::kModel);
  const auto with = [](const char* value) {
    return replaced(small_scene_json(), R"("force": { "multi_rate")",
                    fmt::format(R"("force": {{ "tick_force": {}, "multi_rate")", value));
  };
  const auto exact = parse_scene(with("\"exact\""), "small.json", test_assets());
  ASSERT_TRUE(exact.has_value()) << exact.error().message;
  EXPECT_EQ(exact->force.tick_force, TickForce::kExact);
  const auto bad = parse_scene(with("\"pairs\""), "small.json", test_assets());
  ASSERT_FALSE(bad.has_value());
  EXPECT_NE(bad.error().message.find(R"(field 'force.tick_force': expected "model" or "exact", got "pairs")"),
            std::string::npos)
      << bad.error().message;
}

TEST(Scene, ReadsTheProxyAndNamesItsBadFields) {
  const auto with = [](const char* proxy) {
    return replaced(small_scene_json(), R"("force": { "multi_rate")",
                    fmt::format(R"("force": {{ "proxy": {}, "multi_rate")", proxy));
  };
  const auto on = parse_scene(with(R"({ "enabled": true, "step_m": 0.003, "smoothing_m": 0.0005 })"), "small.json",
                              test_assets());
  ASSERT_TRUE(on.has_value()) << on.error().message;
  EXPECT_TRUE(on->force.proxy.enabled);
  EXPECT_EQ(on->force.proxy.step_m, 0.003);
  EXPECT_EQ(on->force.proxy.smoothing_m, 0.0005);
  const auto expect_error = [&](const char* proxy, const char* needle) {
    const auto bad = parse_scene(with(proxy), "small.json", test_assets());
    ASSERT_FALSE(bad.has_value()) << proxy;
    EXPECT_NE(bad.error().message.find(needle), std::string::npos) << bad.error().message;
  };
  expect_error(R"({ "step_m": -1 })", "force.proxy.step_m");
  expect_error(R"({ "enabled": "yes" })", "force.proxy.enabled");
  expect_error(R"({ "smoothing_m": 0.001 })", "force.proxy.smoothing_m");  // more than step_m / 4
  expect_error(R"({ "stiffness": 1 })", "force.proxy.stiffness");          // unknown field
}

TEST(Scene, ReadsTheSafetyLimitsAndTheRateLimit) {
  const auto defaults = parse_scene(small_scene_json(), "small.json", test_assets());
  ASSERT_TRUE(defaults.has_value()) << defaults.error().message;
  EXPECT_EQ(defaults->safety_limits.max_force_n, 10.0);
  EXPECT_EQ(defaults->safety_limits.max_torque_nm, 0.5);
  EXPECT_EQ(defaults->rate_limit.max_force_n_per_s, 1000.0) << "the rate limit is on by default";
  EXPECT_EQ(defaults->rate_limit.max_torque_nm_per_s, 50.0);
  const std::string with_safety = replaced(
      small_scene_json(), R"("force": { "multi_rate")",
      R"("force": { "safety": { "max_force_n": 2.5, "max_torque_nm": 0.1, "max_force_rate_n_per_s": 300,
                                "max_torque_rate_nm_per_s": 7 }, "multi_rate")");
  const auto scene = parse_scene(with_safety, "small.json", test_assets());
  ASSERT_TRUE(scene.has_value()) << scene.error().message;
  EXPECT_EQ(scene->safety_limits.max_force_n, 2.5);
  EXPECT_EQ(scene->safety_limits.max_torque_nm, 0.1);
  EXPECT_EQ(scene->rate_limit.max_force_n_per_s, 300.0);
  EXPECT_EQ(scene->rate_limit.max_torque_nm_per_s, 7.0);
  EXPECT_EQ(scene->tool().force.max_force_n, 6.0);
  const auto bad = parse_scene(replaced(with_safety, "300", "0"), "small.json", test_assets());
  ASSERT_FALSE(bad.has_value());
  EXPECT_NE(bad.error().message.find("field 'force.safety.max_force_rate_n_per_s': expected a number in"),
            std::string::npos)
      << bad.error().message;
}

// `tools`: several tools, each with its own device; `tool` stays the one-tool spelling
TEST(Scene, ReadsSeveralToolsEachWithItsDevice) {
  const auto scene = parse_scene(testing::two_hands_scene_json(), "hands.json", test_assets());
  ASSERT_TRUE(scene.has_value()) << scene.error().message;
  ASSERT_EQ(scene->tools.size(), 2u);
  EXPECT_EQ(scene->tools[0].name, "left");
  EXPECT_EQ(scene->tools[1].name, "right");
  EXPECT_EQ(scene->tools[1].mode, forcecomp::ForceMode::k3Dof);
  EXPECT_EQ(scene->tools[1].force.max_force_n, 4.0);
  EXPECT_EQ(scene->tools[1].device.config.text("end", ""), "0.15,0,0.048");
  EXPECT_EQ(&scene->tool(), &scene->tools[0]) << "the first tool is the tool";
  const auto one = parse_scene(testing::two_hands_scene_json("right"), "hand.json", test_assets());
  ASSERT_TRUE(one.has_value()) << one.error().message;
  ASSERT_EQ(one->tools.size(), 1u);
  EXPECT_EQ(one->tool().name, "right");
}

TEST(Scene, NamesTheBadFieldOfSeveralTools) {
  const auto error_of = [](const std::string& json) {
    const auto scene = parse_scene(json, "hands.json", test_assets());
    return scene ? std::string("(parsed)") : scene.error().message;
  };
  const std::string both = testing::two_hands_scene_json();
  // both spellings at once
  EXPECT_EQ(error_of(testing::two_hands_scene_json("both", R"(, "tool": { "mesh": "meshes/stylus.obj" })")),
            "hands.json: field 'tools': a scene has either 'tool' (one tool) or 'tools' (a list of tools), "
            "not both");
  // neither
  EXPECT_EQ(
      error_of(testing::replaced(both, R"("tools": [)", R"("tool_list": [)")),
      "hands.json: field 'tool_list': unknown field (known here: name, description, rates, seconds, objects, "
      "tool, tools, watch, force, collision, materials)");
  EXPECT_EQ(
      error_of(R"({ "objects": [{ "name": "ball", "mesh": "meshes/ball.obj" }] })"),
      "hands.json: field 'tool': missing (expected the tool object, or 'tools': a list of tool objects)");
  // an empty list, a list of something else
  EXPECT_EQ(error_of(R"({ "objects": [{ "name": "ball", "mesh": "meshes/ball.obj" }], "tools": [] })"),
            "hands.json: field 'tools': expected a non-empty list of tool objects, got an empty list");
  EXPECT_EQ(error_of(R"({ "objects": [{ "name": "ball", "mesh": "meshes/ball.obj" }], "tools": {} })"),
            "hands.json: field 'tools': expected a non-empty list of tool objects, got object");
  // a field of the second tool, by its place in the list
  EXPECT_EQ(error_of(testing::replaced(both, R"("driver": "sim-line",
                "config": { "start": [0.15)",
                                       R"("driver": 7,
                "config": { "start": [0.15)")),
            "hands.json: field 'tools[1].device.driver': expected a non-empty string, got 7");
  EXPECT_NE(error_of(testing::replaced(both, R"("mode": "3dof")", R"("mode": "2dof")"))
                .find("field 'tools[1].force.mode': expected \"3dof\" or \"6dof\""),
            std::string::npos);
  EXPECT_NE(error_of(testing::replaced(both, R"("name": "right", "mesh")", R"("name": "right", "meshes")"))
                .find("field 'tools[1].meshes': unknown field"),
            std::string::npos);
  EXPECT_EQ(error_of(testing::replaced(both, R"("name": "right")", R"("name": "left")")),
            "hands.json: field 'tools[1].name': duplicate tool name 'left'");
  EXPECT_EQ(error_of(testing::replaced(both, R"("name": "right")", R"("name": "ball")")),
            "hands.json: field 'tools[1].name': 'ball' is also an object's name");
  EXPECT_EQ(error_of(testing::replaced(both, R"("device": { "driver": "sim-line",
                "config": { "start": [0.15)",
                                       R"("devices": { "driver": "sim-line",
                "config": { "start": [0.15)")),
            "hands.json: field 'tools[1].devices': unknown field (known here: name, mesh, ist, spheres, "
            "max_sphere_radius, meters_per_unit, force, device, workspace, material)");
}

TEST(Scene, LoadSceneNamesAMissingFile) {
  const auto scene = load_scene("/nonexistent/scene.json");
  ASSERT_FALSE(scene.has_value());
  EXPECT_NE(scene.error().message.find("/nonexistent/scene.json: cannot open"), std::string::npos);
}

// Paths a scene names are opened as regular files only: a directory, a FIFO or a device is an
// error naming the field and the path, found when the scene is read (not an abort, a hang or an
// endless read when it is packed).
TEST(Scene, RefusesMeshesAndScenesThatAreNotRegularFiles) {
  const auto dir = testing::fresh_cache("not-files");
  const auto fifo = dir / "pipe.obj";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string good = small_scene_json();
  struct Case {
    std::string mesh;
    std::string expected;
  };
  const Case cases[] = {
      {dir.string(), fmt::format("field 'objects[0].mesh': {}: is a directory, not a file", dir.string())},
      {"/dev/zero", "field 'objects[0].mesh': /dev/zero: is a device, not a file"},
      {fifo.string(),
       fmt::format("field 'objects[0].mesh': {}: is a FIFO (named pipe), not a file", fifo.string())},
  };
  for (const Case& c : cases) {
    const auto scene = parse_scene(replaced(good, R"("meshes/bunny_npm_3674.obj")", "\"" + c.mesh + "\""),
                                   "test.json", test_assets());
    ASSERT_FALSE(scene.has_value()) << c.mesh;
    EXPECT_NE(scene.error().message.find(c.expected), std::string::npos) << scene.error().message;
  }
  for (const std::filesystem::path& file : {dir, std::filesystem::path("/dev/zero"), fifo}) {
    const auto scene = load_scene(file);
    ASSERT_FALSE(scene.has_value()) << file;
    EXPECT_EQ(scene.error().message.rfind(file.string() + ": is a", 0), 0u) << scene.error().message;
  }
  std::filesystem::remove_all(dir);
}

// A scene file nested deeper than any scene needs is refused before it is parsed, with the same
// guard as the service's messages (it crashed a server that opened it by path).
TEST(Scene, RefusesJsonNestedDeeperThanTheGuard) {
  const std::string deep = "{\"name\": " + std::string(100000, '[') + std::string(100000, ']') + "}";
  const auto scene = parse(deep);
  ASSERT_FALSE(scene.has_value());
  EXPECT_EQ(scene.error().message, "test.json: the JSON is nested deeper than 32 levels");
  const auto dir = testing::fresh_cache("deep");
  std::ofstream(dir / "deep.json") << deep;
  const auto loaded = load_scene(dir / "deep.json");
  ASSERT_FALSE(loaded.has_value());
  EXPECT_NE(loaded.error().message.find("nested deeper than 32 levels"), std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST(Scene, TheRepositoryScenesParse) {
  for (const char* name : {"bunny_sweep.json", "bunny_deep_throttled.json", "bunny_coupling_circle.json"}) {
    const auto path = test_assets().parent_path() / "scenes" / name;
    if (!std::filesystem::exists(path)) continue;  // scenes added later are covered once they exist
    const auto scene = load_scene(path);
    EXPECT_TRUE(scene.has_value()) << name << ": " << scene.error().message;
  }
  const auto main_scene = load_scene(test_assets().parent_path() / "scenes" / "bunny_sweep.json");
  ASSERT_TRUE(main_scene.has_value()) << main_scene.error().message;
}

TEST(Scene, TheMuseumRoomHasAHundredWatchedObjectsOfThreeShapes) {
  const auto scene = load_scene(test_assets().parent_path() / "scenes" / "museum_room.json");
  ASSERT_TRUE(scene.has_value()) << scene.error().message;
  ASSERT_EQ(scene->objects.size(), 100u);
  EXPECT_EQ(scene->watch.size(), 100u) << "every object is watched: one watcher of the tool against everything";
  std::set<std::string> names, meshes;
  for (const SceneObject& o : scene->objects) {
    names.insert(o.name);
    meshes.insert(o.shape.mesh.filename().string());
    EXPECT_TRUE(std::filesystem::exists(o.shape.mesh)) << o.shape.mesh;
    EXPECT_EQ(o.shape.spheres, 10000);
  }
  EXPECT_EQ(names.size(), 100u);
  EXPECT_EQ(meshes, (std::set<std::string>{"bunny_npm_3674.obj", "torus.obj", "vase.obj"}));
}

TEST(Scene, DefaultSceneIsEmbeddedAndWritesItsMeshes) {
  const auto cache = testing::fresh_cache("default");
  const auto scene = default_scene(cache);
  ASSERT_TRUE(scene.has_value()) << scene.error().message;
  EXPECT_EQ(scene->name, "bunny-sweep");
  EXPECT_TRUE(std::filesystem::exists(scene->objects.at(0).shape.mesh));
  EXPECT_TRUE(std::filesystem::exists(scene->tool().shape.mesh));
  std::filesystem::remove_all(cache);
}

TEST(Scene, ShapeTreesAreBuiltOnceThenLoadedFromTheCacheInMetres) {
  const auto cache = testing::fresh_cache("tree-cache");
  SceneShape shape{.mesh = test_assets() / "meshes" / "stylus.obj", .spheres = 120, .meters_per_unit = 0.01};
  int progress_calls = 0;
  const auto first = load_shape_tree(shape, cache, [&](const std::string&, double) { ++progress_calls; });
  ASSERT_TRUE(first.has_value()) << first.error().message;
  EXPECT_GT(progress_calls, 0) << "a build reports progress";
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(cache)) files += entry.path().extension() == ".ist";
  EXPECT_EQ(files, 1);
  // stylus: 5 cm long capsule of radius 4 mm; the root sphere encloses it
  EXPECT_NEAR(first->tree->root().radius, 0.025, 0.003);
  // the packing's coverage travels with the tree (the gradient force law is calibrated by it)
  EXPECT_GT(first->coverage, 0.3);
  EXPECT_LT(first->coverage, 1.0);

  progress_calls = 0;
  const auto second = load_shape_tree(shape, cache, [&](const std::string&, double) { ++progress_calls; });
  ASSERT_TRUE(second.has_value());
  EXPECT_EQ(progress_calls, 0) << "the cached .ist is loaded, not rebuilt";
  EXPECT_EQ(second->tree->leaf_count(), first->tree->leaf_count());
  EXPECT_EQ(second->coverage, first->coverage);

  // a corrupted cache file is rebuilt, not trusted
  for (const auto& entry : std::filesystem::directory_iterator(cache)) {
    std::fstream f(entry.path(), std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(200);
    f.put('\x5a');
  }
  const auto third = load_shape_tree(shape, cache, [&](const std::string&, double) { ++progress_calls; });
  ASSERT_TRUE(third.has_value()) << third.error().message;
  EXPECT_GT(progress_calls, 0);

  // a bound on the radius is part of the cache key: a packing of its own, every sphere within it
  shape.max_sphere_radius = 0.002;  // [m]: 0.2 mesh units
  progress_calls = 0;
  const auto bounded = load_shape_tree(shape, cache, [&](const std::string&, double) { ++progress_calls; });
  ASSERT_TRUE(bounded.has_value()) << bounded.error().message;
  EXPECT_GT(progress_calls, 0) << "not the unbounded packing from the cache";
  files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(cache))
    files += entry.path().extension() == ".ist";
  EXPECT_EQ(files, 2);
  float largest = 0.f;
  for (const Sphere& s : bounded->tree->leaves()) largest = std::max(largest, s.radius);
  EXPECT_LE(largest, 0.002f * (1.f + 1e-6f));
  EXPECT_GT(largest, 0.0019f);
  float unbounded_largest = 0.f;
  for (const Sphere& s : first->tree->leaves()) unbounded_largest = std::max(unbounded_largest, s.radius);
  EXPECT_GT(unbounded_largest, 0.003f) << "the stylus is 4 mm thick: unbounded, its spheres are larger";
  std::filesystem::remove_all(cache);
}

}  // namespace
}  // namespace uh::controllers
