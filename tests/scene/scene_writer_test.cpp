// The scene writer against the files people wrote: every committed scene, read and written, says
// everything its file said (each value the file gives is in the written file at the same place,
// materials named in a table resolved), and the written file reads back to a scene that writes
// the same text again. The references are the hand-written files themselves, not the writer.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "../controllers/scene_test_support.hpp"
#include "uh/collette/sphere_tree.hpp"
#include "uh/scene/scene.hpp"
#include "uh/scene/validate.hpp"

namespace uh::scene {
namespace {

using nlohmann::json;

bool same_number(double a, double b) { return std::abs(a - b) <= 1e-12 * std::max(1.0, std::abs(a)); }

// a file's rotation or grating direction as it is read: normalised
json normalised(const json& q) {
  double n = 0.0;
  for (const json& v : q) n += v.get<double>() * v.get<double>();
  json out = json::array();
  for (const json& v : q) out.push_back(v.get<double>() / std::sqrt(n));
  return out;
}

// Every leaf of `given` (what a file says) is in `written` at the same path, as the same value.
void expect_said(const json& given, const json& written, const std::string& path) {
  SCOPED_TRACE(path);
  if (given.is_object()) {
    ASSERT_TRUE(written.is_object()) << written.dump();
    for (const auto& [key, value] : given.items()) {
      ASSERT_TRUE(written.contains(key)) << "the written file lacks '" << key << "'";
      expect_said(value, written[key], path + "." + key);
    }
  } else if (given.is_array()) {
    ASSERT_TRUE(written.is_array() && written.size() == given.size()) << written.dump();
    const auto ends_with = [&](const std::string& tail) {
      return path.size() >= tail.size() && path.compare(path.size() - tail.size(), tail.size(), tail) == 0;
    };
    const json expected = ends_with("rotation") || ends_with("direction") ? normalised(given) : given;
    for (std::size_t i = 0; i < given.size(); ++i) expect_said(expected[i], written[i], path + "[" + std::to_string(i) + "]");
  } else if (given.is_boolean() && written.is_number()) {
    EXPECT_EQ(written.get<double>(), given.get<bool>() ? 1.0 : 0.0);  // a device setting is text: 1 or 0
  } else if (given.is_number()) {
    ASSERT_TRUE(written.is_number()) << written.dump();
    EXPECT_TRUE(same_number(given.get<double>(), written.get<double>())) << given << " written as " << written;
  } else {
    EXPECT_EQ(given, written);
  }
}

// What a hand-written file says, in the writer's terms: `tool` is `tools[0]`, a material named in
// the file's table is that entry, paths and the free-text description are left out.
json as_said(json file) {
  const json table = file.value("materials", json::object());
  file.erase("materials");
  file.erase("description");
  if (file.contains("tool")) {
    file["tools"] = json::array({file["tool"]});
    file.erase("tool");
  }
  for (const char* list : {"objects", "tools"})
    for (json& part : file[list]) {
      part.erase("mesh");
      part.erase("ist");
      if (part.contains("material") && part["material"].is_string()) part["material"] = table.at(part["material"].get<std::string>());
      if (part.contains("device") && part["device"].contains("config")) part["device"]["config"].erase("file");
    }
  return file;
}

TEST(SceneWriter, EveryCommittedSceneIsWrittenWithAllItSaysAndReadsBackToItself) {
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(std::filesystem::path(UH_TEST_DATA_DIR).parent_path() / "scenes")) {
    if (entry.path().extension() != ".json") continue;
    SCOPED_TRACE(entry.path().filename().string());
    ++files;
    const auto scene = load_scene(entry.path());
    ASSERT_TRUE(scene.has_value()) << scene.error().message;
    const auto text = write_scene(*scene);
    ASSERT_TRUE(text.has_value()) << text.error().message;
    std::ifstream in(entry.path());
    expect_said(as_said(json::parse(in)), json::parse(*text), "");
    // the written file reads back to the scene, which writes the same file again
    const auto again = parse_scene(*text, "written.json", entry.path().parent_path());
    ASSERT_TRUE(again.has_value()) << again.error().message;
    const auto text_again = write_scene(*again);
    ASSERT_TRUE(text_again.has_value()) << text_again.error().message;
    expect_said(json::parse(*text), json::parse(*text_again), "");
    EXPECT_EQ(again->objects.size(), scene->objects.size());
    EXPECT_EQ(again->tools.size(), scene->tools.size());
    for (std::size_t i = 0; i < scene->objects.size(); ++i) EXPECT_EQ(again->objects[i].shape.mesh, scene->objects[i].shape.mesh);
  }
  EXPECT_GE(files, 10);
}

TEST(SceneWriter, ADeformableObjectReadsBackToItself) {
  nlohmann::json j = json::parse(controllers::testing::small_scene_json());
  j["objects"][0]["deformable"] = {{"young_modulus_pa", 2.5e4},
                                   {"poisson_ratio", 0.4},
                                   {"density_kg_m3", 1100.0},
                                   {"damping", 0.02},
                                   {"tetrahedra", 1500},
                                   {"fixed", {{"box", {{-0.1, -0.1, -0.1}, {0.1, 0.1, -0.02}}}}}};
  const auto scene = parse_scene(j.dump(), "soft.json", controllers::testing::test_assets());
  ASSERT_TRUE(scene.has_value()) << scene.error().message;
  const auto text = write_scene(*scene);
  ASSERT_TRUE(text.has_value()) << text.error().message;
  expect_said(j["objects"][0]["deformable"], json::parse(*text)["objects"][0]["deformable"], "deformable");
  const auto again = parse_scene(*text, "written.json", controllers::testing::test_assets());
  ASSERT_TRUE(again.has_value()) << again.error().message;
  ASSERT_TRUE(again->objects[0].deformable.has_value());
  const SceneDeformable& d = *again->objects[0].deformable;
  EXPECT_EQ(d.young_modulus_pa, 2.5e4);
  EXPECT_EQ(d.poisson_ratio, 0.4);
  EXPECT_EQ(d.density_kg_m3, 1100.0);
  EXPECT_EQ(d.damping, 0.02);
  EXPECT_EQ(d.tetrahedra, 1500);
  ASSERT_TRUE(d.fixed_box.has_value());
  EXPECT_EQ(d.fixed_box->min.z, -0.1);
  EXPECT_EQ(d.fixed_box->max.z, -0.02);
  // a rigid object stays rigid, and a soft one without `tetrahedra` or `fixed` keeps neither
  EXPECT_FALSE(json::parse(*write_scene(*parse_scene(controllers::testing::small_scene_json(), "small.json",
                                                     controllers::testing::test_assets())))["objects"][0]
                   .contains("deformable"));
  j["objects"][0]["deformable"] = json::object();
  const auto bare = parse_scene(j.dump(), "bare.json", controllers::testing::test_assets());
  ASSERT_TRUE(bare.has_value()) << bare.error().message;
  const json written = json::parse(*write_scene(*bare))["objects"][0]["deformable"];
  EXPECT_FALSE(written.contains("tetrahedra"));
  EXPECT_FALSE(written.contains("fixed"));
  EXPECT_EQ(written["young_modulus_pa"], SceneDeformable{}.young_modulus_pa);
}

TEST(SceneWriter, RefusesATreeHeldOnlyInMemoryAndAnInvalidScene) {
  auto scene = parse_scene(controllers::testing::small_scene_json(), "small.json", controllers::testing::test_assets());
  ASSERT_TRUE(scene.has_value()) << scene.error().message;
  Scene in_memory = *scene;
  in_memory.objects[0].shape.mesh.clear();
  in_memory.objects[0].shape.tree = std::make_shared<const collette::SphereTree>();
  const auto refused = write_scene(in_memory);
  ASSERT_FALSE(refused.has_value());
  EXPECT_NE(refused.error().message.find("objects[0] 'bunny': its tree is held in memory"), std::string::npos)
      << refused.error().message;
  Scene invalid = *scene;
  invalid.haptic_hz = 0.5;
  const auto bad = write_scene(invalid);
  ASSERT_FALSE(bad.has_value());
  EXPECT_NE(bad.error().message.find("rates.haptic_hz"), std::string::npos) << bad.error().message;
}

}  // namespace
}  // namespace uh::scene
