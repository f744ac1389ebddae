// Materials in scene files: inline and named, for objects and the tool; every bad value refused
// with the file and the field named.

#include <gtest/gtest.h>

#include "scene_test_support.hpp"
#include "uh/controllers/scene.hpp"

namespace uh::controllers {
namespace {

using testing::replaced;
using testing::small_scene_json;
using testing::test_assets;

Result<Scene> parse(const std::string& text) { return parse_scene(text, "test.json", test_assets()); }

// the small scene with `materials` at the top and `material` on the bunny
std::string with_material(const std::string& object_material, const std::string& table = "{}") {
  std::string s =
      replaced(small_scene_json(), R"("rates":)", fmt::format(R"("materials": {}, "rates":)", table));
  return replaced(s, R"("spheres": 600,)",
                  fmt::format(R"("spheres": 600, "material": {},)", object_material));
}

void expect_error(const std::string& text, const std::string& needle) {
  const auto scene = parse(text);
  ASSERT_FALSE(scene.has_value()) << "expected an error containing: " << needle;
  EXPECT_NE(scene.error().message.find(needle), std::string::npos) << scene.error().message;
  EXPECT_EQ(scene.error().message.rfind("test.json", 0), 0u) << scene.error().message;
}

TEST(SceneMaterials, WithoutMaterialsNothingChanges) {
  const auto scene = parse(small_scene_json());
  ASSERT_TRUE(scene.has_value()) << scene.error().message;
  const forcecomp::Material& m = scene->objects[0].material;
  EXPECT_FALSE(m.has_stiffness || m.has_damping || m.has_friction);
  EXPECT_EQ(m.texture.kind, forcecomp::TextureKind::kNone);
  const auto combined = forcecomp::combine_materials(m, scene->tool().material, scene->tool().force);
  EXPECT_EQ(combined.stiffness, scene->tool().force.stiffness);
  EXPECT_EQ(combined.damping, scene->tool().force.damping);
  EXPECT_FALSE(combined.has_friction() || combined.has_texture());
}

TEST(SceneMaterials, ReadsInlineAndNamedMaterials) {
  const auto scene = parse(with_material(
      R"("stone")",
      R"({ "stone": { "stiffness": 3e4, "damping": 0.5, "friction": { "static": 0.6, "dynamic": 0.4 },
                      "texture": { "type": "grating", "period": 0.003, "amplitude": 1e-4, "direction": [0, 2, 0] } },
           "resin": { "texture": { "type": "random", "roughness": 2e-5, "correlation_length": 0.001, "seed": 4 } } })"));
  ASSERT_TRUE(scene.has_value()) << scene.error().message;
  const forcecomp::Material& m = scene->objects[0].material;
  EXPECT_TRUE(m.has_stiffness);
  EXPECT_EQ(m.stiffness, 3e4);
  EXPECT_EQ(m.damping, 0.5);
  EXPECT_EQ(m.friction_static, 0.6);
  EXPECT_EQ(m.friction_dynamic, 0.4);
  EXPECT_EQ(m.texture.kind, forcecomp::TextureKind::kGrating);
  EXPECT_EQ(m.texture.period_m, 0.003);
  EXPECT_EQ(m.texture.direction, (Vec3{0, 1, 0}));

  const auto tool =
      parse(replaced(small_scene_json(), R"("name": "stylus",)",
                     R"("name": "stylus", "material": { "friction": { "static": 0.3, "dynamic": 0.3 } },)"));
  ASSERT_TRUE(tool.has_value()) << tool.error().message;
  EXPECT_TRUE(tool->tool().material.has_friction);
}

TEST(SceneMaterials, EveryBadValueIsRefusedWithTheFileAndTheField) {
  expect_error(with_material(R"("marble")"), "field 'objects[0].material': no material is named 'marble'");
  expect_error(with_material("7"), "field 'objects[0].material': expected an object");
  expect_error(with_material(R"({ "stifness": 1 })"), "field 'objects[0].material.stifness': unknown field");
  expect_error(with_material(R"({ "stiffness": 0 })"),
               "field 'objects[0].material.stiffness': expected a number in");
  expect_error(with_material(R"({ "stiffness": "hard" })"),
               "field 'objects[0].material.stiffness': expected a number");
  expect_error(with_material(R"({ "damping": -1 })"),
               "field 'objects[0].material.damping': expected a number in");
  expect_error(with_material(R"({ "friction": 0.5 })"),
               "field 'objects[0].material.friction': expected an object");
  expect_error(with_material(R"({ "friction": { "static": 0.5 } })"),
               "field 'objects[0].material.friction': expected both 'static'");
  expect_error(with_material(R"({ "friction": { "static": -0.5, "dynamic": 0.1 } })"),
               "field 'objects[0].material.friction.static': expected a number in [0, 10]");
  expect_error(with_material(R"({ "friction": { "static": 0.2, "dynamic": 0.4 } })"),
               "field 'objects[0].material.friction.dynamic': is above 'static'");
  expect_error(with_material(R"({ "texture": { "period": 0.001 } })"),
               "field 'objects[0].material.texture.type': missing");
  expect_error(with_material(R"({ "texture": { "type": "bumpy" } })"),
               "field 'objects[0].material.texture.type': expected \"grating\" or \"random\"");
  expect_error(with_material(R"({ "texture": { "type": "grating", "amplitude": 1e-4 } })"),
               "field 'objects[0].material.texture': a grating needs 'period'");
  expect_error(with_material(R"({ "texture": { "type": "grating", "period": 0, "amplitude": 1e-4 } })"),
               "field 'objects[0].material.texture.period': expected a number in");
  expect_error(with_material(R"({ "texture": { "type": "grating", "period": 0.002, "amplitude": 1 } })"),
               "field 'objects[0].material.texture.amplitude': expected a number in [0, 0.01]");
  expect_error(
      with_material(
          R"({ "texture": { "type": "grating", "period": 0.002, "amplitude": 1e-4, "direction": [0, 0, 0] } })"),
      "field 'objects[0].material.texture.direction': expected a non-zero");
  expect_error(
      with_material(
          R"({ "texture": { "type": "grating", "period": 0.002, "amplitude": 1e-4, "roughness": 1e-5 } })"),
      "field 'objects[0].material.texture.roughness': unknown field");
  expect_error(
      with_material(R"({ "texture": { "type": "random", "roughness": 1e-5 } })"),
      "field 'objects[0].material.texture': a random texture needs 'roughness' [m] and 'correlation_length'");
  expect_error(with_material(
                   R"({ "texture": { "type": "random", "roughness": -1e-5, "correlation_length": 0.001 } })"),
               "field 'objects[0].material.texture.roughness': expected a number in");
  expect_error(
      with_material(R"({ "texture": { "type": "random", "roughness": 1e-5, "correlation_length": 0 } })"),
      "field 'objects[0].material.texture.correlation_length': expected a number in");
  expect_error(
      with_material(
          R"({ "texture": { "type": "random", "roughness": 1e-5, "correlation_length": 0.001, "seed": 1.5 } })"),
      "field 'objects[0].material.texture.seed': expected a whole number");
  // every field's every other way to be wrong: out of range above, of the wrong type, unknown
  const std::pair<std::string, std::string> more_cases[] = {
      {R"({ "stiffness": 1e13 })", "field 'objects[0].material.stiffness': expected a number in"},
      {R"({ "damping": 1e7 })", "field 'objects[0].material.damping': expected a number in"},
      {R"({ "friction": { "static": 0.5, "dynamic": -0.1 } })",
       "field 'objects[0].material.friction.dynamic': expected a number in [0, 10]"},
      {R"({ "friction": { "static": 11, "dynamic": 0.1 } })",
       "field 'objects[0].material.friction.static': expected a number in [0, 10]"},
      {R"({ "friction": { "static": 0.5, "dynamic": "low" } })",
       "field 'objects[0].material.friction.dynamic': expected a number"},
      {R"({ "friction": { "static": 0.5, "dynamic": 0.1, "kinetic": 0.1 } })",
       "field 'objects[0].material.friction.kinetic': unknown field"},
      {R"({ "texture": "ridges" })", "field 'objects[0].material.texture': expected an object"},
      {R"({ "texture": { "type": 2 } })",
       "field 'objects[0].material.texture.type': expected a non-empty string"},
      {R"({ "texture": { "type": "grating", "period": 0.002 } })",
       "field 'objects[0].material.texture': a grating needs 'period' [m] and 'amplitude' [m]"},
      {R"({ "texture": { "type": "grating", "period": 2, "amplitude": 1e-4 } })",
       "field 'objects[0].material.texture.period': expected a number in"},
      {R"({ "texture": { "type": "grating", "period": 0.002, "amplitude": -1e-4 } })",
       "field 'objects[0].material.texture.amplitude': expected a number in [0, 0.01]"},
      {R"({ "texture": { "type": "grating", "period": 0.002, "amplitude": 1e-4, "direction": [1, 0] } })",
       "field 'objects[0].material.texture.direction': expected [x, y, z]"},
      {R"({ "texture": { "type": "grating", "period": 0.002, "amplitude": 1e-4, "direction": [1, "y", 0] } })",
       "field 'objects[0].material.texture.direction': expected [x, y, z] of numbers"},
      {R"({ "texture": { "type": "random", "roughness": 1e-5, "correlation_length": 0.001, "period": 0.002 } })",
       "field 'objects[0].material.texture.period': unknown field"},
      {R"({ "texture": { "type": "random", "roughness": 0.1, "correlation_length": 0.001 } })",
       "field 'objects[0].material.texture.roughness': expected a number in [0, 0.01]"},
      {R"({ "texture": { "type": "random", "roughness": 1e-5, "correlation_length": 2 } })",
       "field 'objects[0].material.texture.correlation_length': expected a number in"},
      {R"({ "texture": { "type": "random", "roughness": "fine", "correlation_length": 0.001 } })",
       "field 'objects[0].material.texture.roughness': expected a number"},
      {R"({ "texture": { "type": "random", "roughness": 1e-5, "correlation_length": 0.001, "seed": -1 } })",
       "field 'objects[0].material.texture.seed': expected a whole number in"},
  };
  for (const auto& [material, needle] : more_cases) expect_error(with_material(material), needle);
  expect_error(with_material(R"(null)"), "field 'objects[0].material': expected an object");
  expect_error(with_material(R"("x")", R"({ "x": 3 })"), "field 'materials.x': expected an object");
  expect_error(with_material(R"("x")", R"({ "x": { "friction": { "static": 0.1, "dynamic": 0.2 } } })"),
               "field 'materials.x.friction.dynamic': is above 'static'");
  expect_error(
      replaced(small_scene_json(), R"("name": "stylus",)", R"("name": "stylus", "material": "felt",)"),
      "field 'tool.material': no material is named 'felt' (the scene's 'materials' has none)");
  // named entries are checked under their own path
  expect_error(with_material(R"("x")", R"({ "x": { "damping": "lots" } })"),
               "field 'materials.x.damping': expected a number");
  expect_error(with_material(R"("x")", R"([1])"), "field 'materials': expected an object of named materials");
  // the tool's material too, and a stiffness under the paper law
  expect_error(replaced(small_scene_json(), R"("name": "stylus",)",
                        R"("name": "stylus", "material": { "friction": {} },)"),
               "field 'tool.material.friction': expected both");
  expect_error(replaced(replaced(with_material(R"({ "stiffness": 1e4 })"), R"("stiffness": 1.6e4)",
                                 R"("force_scale": 8.0e6)"),
                        R"("mode": "6dof")", R"("mode": "6dof", "law": "paper")"),
               "field 'objects[0].material.stiffness': is the gradient law's stiffness [N/m^2]; this scene "
               "uses the paper law");
}

}  // namespace
}  // namespace uh::controllers
