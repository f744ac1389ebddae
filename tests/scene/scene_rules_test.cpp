// Each documented range of a scene field is enforced identically by the file parser, by
// validate() on a scene built in memory and by the session's creation (the C API's setters:
// scene_rules_capi_test.cpp, against the same table).

#include <gtest/gtest.h>

#include <functional>
#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "../controllers/scene_test_support.hpp"
#include "scene_ranges.hpp"
#include "uh/controllers/haptic_session.hpp"
#include "uh/scene/validate.hpp"

namespace uh::scene {
namespace {

using controllers::testing::small_scene_json;
using controllers::testing::test_assets;
using testing::FieldRange;
using testing::kFieldRanges;

using Setter = std::function<void(Scene&, double)>;

// the first object's deformable part, made soft (defaults) when it was rigid
SceneDeformable& deformable(Scene& s) {
  if (!s.objects[0].deformable) s.objects[0].deformable.emplace();
  return *s.objects[0].deformable;
}

// How each field of the table is set on a scene in memory.
const std::map<std::string, Setter>& setters() {
  static const std::map<std::string, Setter> table{
      {"seconds", [](Scene& s, double v) { s.seconds = v; }},
      {"rates.haptic_hz", [](Scene& s, double v) { s.haptic_hz = v; }},
      {"rates.collision_hz", [](Scene& s, double v) { s.collision_hz = v; }},
      {"collision.contact_margin", [](Scene& s, double v) { s.contact_margin = v; }},
      {"collision.coherence_skin", [](Scene& s, double v) { s.coherence_skin = v; }},
      {"objects[0].spheres", [](Scene& s, double v) { s.objects[0].shape.spheres = static_cast<std::int64_t>(v); }},
      {"objects[0].meters_per_unit", [](Scene& s, double v) { s.objects[0].shape.meters_per_unit = v; }},
      {"objects[0].max_sphere_radius", [](Scene& s, double v) { s.objects[0].shape.max_sphere_radius = v; }},
      {"objects[0].material.stiffness",
       [](Scene& s, double v) {
         s.objects[0].material.has_stiffness = true;
         s.objects[0].material.stiffness = v;
       }},
      {"objects[0].material.damping",
       [](Scene& s, double v) {
         s.objects[0].material.has_damping = true;
         s.objects[0].material.damping = v;
       }},
      {"objects[0].deformable.young_modulus_pa",
       [](Scene& s, double v) { deformable(s).young_modulus_pa = v; }},
      {"objects[0].deformable.poisson_ratio", [](Scene& s, double v) { deformable(s).poisson_ratio = v; }},
      {"objects[0].deformable.density_kg_m3", [](Scene& s, double v) { deformable(s).density_kg_m3 = v; }},
      {"objects[0].deformable.damping", [](Scene& s, double v) { deformable(s).damping = v; }},
      {"objects[0].deformable.tetrahedra",
       [](Scene& s, double v) { deformable(s).tetrahedra = static_cast<std::int64_t>(v); }},
      {"objects[0].deformable.rate_hz", [](Scene& s, double v) { deformable(s).rate_hz = v; }},
      {"tool.spheres", [](Scene& s, double v) { s.tool().shape.spheres = static_cast<std::int64_t>(v); }},
      {"tool.meters_per_unit", [](Scene& s, double v) { s.tool().shape.meters_per_unit = v; }},
      {"tool.force.stiffness", [](Scene& s, double v) { s.tool().force.stiffness = v; }},
      {"tool.force.damping", [](Scene& s, double v) { s.tool().force.damping = v; }},
      {"tool.force.damping_full_volume", [](Scene& s, double v) { s.tool().force.damping_full_volume = v; }},
      {"tool.force.mass_kg", [](Scene& s, double v) { s.tool().force.mass_kg = v; }},
      {"tool.force.max_force_n", [](Scene& s, double v) { s.tool().force.max_force_n = v; }},
      {"tool.force.max_torque_nm", [](Scene& s, double v) { s.tool().force.max_torque_nm = v; }},
      {"tool.workspace.scale", [](Scene& s, double v) { s.tool().workspace.scale = v; }},
      {"force.safety.max_force_n", [](Scene& s, double v) { s.safety_limits.max_force_n = v; }},
      {"force.safety.max_torque_nm", [](Scene& s, double v) { s.safety_limits.max_torque_nm = v; }},
      {"force.safety.max_force_rate_n_per_s", [](Scene& s, double v) { s.rate_limit.max_force_n_per_s = v; }},
      {"force.safety.max_torque_rate_nm_per_s", [](Scene& s, double v) { s.rate_limit.max_torque_nm_per_s = v; }},
      {"force.safety.watchdog_max_age_s", [](Scene& s, double v) { s.force.safety.watchdog.max_age_s = v; }},
      {"force.safety.watchdog_ramp_s", [](Scene& s, double v) { s.force.safety.watchdog.ramp_s = v; }},
      {"force.coupling.stiffness", [](Scene& s, double v) { s.force.coupling.stiffness = v; }},
      {"force.coupling.damping", [](Scene& s, double v) { s.force.coupling.damping = v; }},
      {"force.coupling.passivity_margin", [](Scene& s, double v) { s.force.coupling.passivity_margin = v; }},
      {"force.coupling.proxy_mass_kg", [](Scene& s, double v) { s.force.coupling.proxy_mass_kg = v; }},
      {"force.proxy.step_m", [](Scene& s, double v) { s.force.proxy.step_m = v; }},
      {"force.proxy.penetration_m", [](Scene& s, double v) { s.force.proxy.penetration_m = v; }},
  };
  return table;
}

// `objects[0].material.stiffness` as the JSON pointer /objects/0/material/stiffness
nlohmann::json::json_pointer pointer(std::string path) {
  std::string out;
  for (char c : path) {
    if (c == '.' || c == '[') {
      out += '/';
    } else if (c != ']') {
      out += c;
    }
  }
  return nlohmann::json::json_pointer("/" + out);
}

std::string scene_text_with(const FieldRange& f, double value) {
  nlohmann::json j = nlohmann::json::parse(small_scene_json());
  if (f.whole)
    j[pointer(f.path)] = static_cast<std::int64_t>(value);
  else
    j[pointer(f.path)] = value;
  return j.dump();
}

Scene good_scene() {
  auto scene = parse_scene(small_scene_json(), "rules.json", test_assets());
  EXPECT_TRUE(scene.has_value()) << scene.error().message;
  return *scene;
}

TEST(SceneRules, EveryFieldOfTheTableHasASetter) {
  for (const FieldRange& f : kFieldRanges) EXPECT_TRUE(setters().contains(f.path)) << f.path;
  EXPECT_EQ(setters().size(), kFieldRanges.size());
}

TEST(SceneRules, TheFileTheModelAndTheSessionRefuseTheSameValuesAlike) {
  for (const FieldRange& f : kFieldRanges) {
    for (const double value : {testing::below(f), testing::above(f)}) {
      SCOPED_TRACE(fmt::format("{} = {}", f.path, value));
      const std::string expected = testing::range_message(f, value);

      const auto parsed = parse_scene(scene_text_with(f, value), "rules.json", test_assets());
      ASSERT_FALSE(parsed.has_value());
      EXPECT_EQ(parsed.error().message, "rules.json: " + expected);

      Scene scene = good_scene();
      scene.source = "rules.json";
      setters().at(f.path)(scene, value);
      const Status valid = validate(scene);
      ASSERT_FALSE(valid);
      EXPECT_EQ(valid.error().message, expected);
      EXPECT_EQ(valid.error().kind, ErrorKind::kInvalid);

      const auto session = controllers::HapticSession::create(scene);
      ASSERT_FALSE(session.has_value());
      EXPECT_EQ(session.error().message, "rules.json: " + expected);
    }
  }
}

TEST(SceneRules, TheBoundsThemselvesAreAccepted) {
  for (const FieldRange& f : kFieldRanges) {
    for (const double value : {f.min, f.max}) {
      SCOPED_TRACE(fmt::format("{} = {}", f.path, value));
      Scene scene = good_scene();
      setters().at(f.path)(scene, value);
      // the bounds of one field may break a rule between fields (a proxy step below four times
      // its smoothing): that rule is then the one named, never this field's range
      const Status valid = validate(scene);
      if (!valid) {
        EXPECT_EQ(valid.error().message.find(fmt::format("field '{}': expected", f.path)), std::string::npos);
      }
      const auto parsed = parse_scene(scene_text_with(f, value), "rules.json", test_assets());
      EXPECT_EQ(parsed.has_value(), static_cast<bool>(valid)) << (parsed ? "" : parsed.error().message);
    }
  }
}

TEST(SceneRules, TheSessionChecksItsOwnOverridesAsScenes) {
  // the session's rate was once (0, 10000] while the file's is [1, 10000]: one range now
  const Scene scene = good_scene();
  controllers::SessionOptions options;
  options.haptic_hz = 0.5;
  const auto session = controllers::HapticSession::create(scene, options);
  ASSERT_FALSE(session.has_value());
  EXPECT_NE(session.error().message.find("field 'rates.haptic_hz': expected a number in [1, 10000], got 0.5"),
            std::string::npos)
      << session.error().message;
}

TEST(SceneRules, RulesBetweenFieldsNameTheField) {
  Scene scene = good_scene();
  scene.objects[0].material.has_friction = true;
  scene.objects[0].material.friction_static = 0.3;
  scene.objects[0].material.friction_dynamic = 0.5;
  Status valid = validate(scene);
  ASSERT_FALSE(valid);
  EXPECT_EQ(valid.error().message.rfind("field 'objects[0].material.friction.dynamic': is above 'static'", 0), 0u)
      << valid.error().message;

  scene = good_scene();
  scene.tool().force.law = forcecomp::ForceLaw::kPaper;
  scene.objects[0].material.has_stiffness = true;
  scene.objects[0].material.stiffness = 1e4;
  valid = validate(scene);
  ASSERT_FALSE(valid);
  EXPECT_EQ(valid.error().message.rfind("field 'objects[0].material.stiffness': is the gradient law's stiffness", 0), 0u)
      << valid.error().message;

  scene = good_scene();
  scene.watch.push_back("nobody");
  valid = validate(scene);
  ASSERT_FALSE(valid);
  EXPECT_EQ(valid.error().message, "field 'watch[1]': no object is named 'nobody'");

  scene = good_scene();
  scene.tools.push_back(scene.tool());
  valid = validate(scene);
  ASSERT_FALSE(valid);
  EXPECT_EQ(valid.error().message, "field 'tools[1].name': duplicate tool name 'stylus'");

  scene = good_scene();
  scene.objects[0].shape.mesh = test_assets() / "meshes" / "no-such-mesh.obj";
  valid = validate(scene);
  ASSERT_FALSE(valid);
  EXPECT_EQ(valid.error().message.rfind("field 'objects[0].mesh': file not found: ", 0), 0u) << valid.error().message;
}

TEST(SceneRules, ADeformableObjectsBoxAndShapeAreChecked) {
  Scene scene = good_scene();
  deformable(scene).fixed_box = SceneDeformable::Box{.min = {0.0, 0.0, 0.01}, .max = {0.1, 0.1, 0.0}};
  Status valid = validate(scene);
  ASSERT_FALSE(valid);
  EXPECT_EQ(valid.error().message.rfind("field 'objects[0].deformable.fixed.box': expected [[x0, y0, z0], [x1, y1, z1]] "
                                        "with x0 <= x1",
                                        0),
            0u)
      << valid.error().message;

  scene = good_scene();
  deformable(scene);
  scene.objects[0].shape.ist = scene.objects[0].shape.mesh;  // a regular file: only its kind matters here
  scene.objects[0].shape.mesh.clear();
  valid = validate(scene);
  ASSERT_FALSE(valid);
  EXPECT_NE(valid.error().message.find("field 'objects[0].deformable': a deformable object needs a 'mesh'"),
            std::string::npos)
      << valid.error().message;

  // the file: a box of one corner, a corner of two numbers, an unknown field
  nlohmann::json j = nlohmann::json::parse(small_scene_json());
  j["objects"][0]["deformable"] = {{"fixed", {{"box", {{0, 0, 0}}}}}};
  auto parsed = parse_scene(j.dump(), "soft.json", test_assets());
  ASSERT_FALSE(parsed.has_value());
  EXPECT_EQ(parsed.error().message.rfind("soft.json: field 'objects[0].deformable.fixed.box': expected [[x0", 0), 0u)
      << parsed.error().message;
  j["objects"][0]["deformable"] = {{"fixed", {{"box", {{0, 0, 0}, {1, 1}}}}}};
  parsed = parse_scene(j.dump(), "soft.json", test_assets());
  ASSERT_FALSE(parsed.has_value());
  EXPECT_EQ(parsed.error().message.rfind("soft.json: field 'objects[0].deformable.fixed.box[1]': expected [x, y, z]", 0), 0u)
      << parsed.error().message;
  j["objects"][0]["deformable"] = {{"youngs_modulus", 1e5}};
  parsed = parse_scene(j.dump(), "soft.json", test_assets());
  ASSERT_FALSE(parsed.has_value());
  EXPECT_EQ(parsed.error().message.rfind("soft.json: field 'objects[0].deformable.youngs_modulus': unknown field", 0), 0u)
      << parsed.error().message;
}

TEST(SceneRules, TheCommittedScenesAreValid) {
  // the shipped scenes and the benchmarks' own (bench/soft/soft_block_5k.json)
  const auto root = std::filesystem::path(UH_TEST_DATA_DIR).parent_path();
  int checked = 0;
  for (const auto& folder : {root / "scenes", root / "bench" / "soft"}) {
    for (const auto& entry : std::filesystem::directory_iterator(folder)) {
      if (entry.path().extension() != ".json") continue;
      SCOPED_TRACE(entry.path().string());
      const auto scene = load_scene(entry.path());
      ASSERT_TRUE(scene.has_value()) << scene.error().message;
      EXPECT_TRUE(validate(*scene));
      ++checked;
    }
  }
  EXPECT_GT(checked, 10);
}

}  // namespace
}  // namespace uh::scene
