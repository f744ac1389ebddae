// The C API's setters refuse a scene field outside its documented range with the message the
// scene file and the session give (scene_ranges.hpp; scene_rules_test.cpp holds the others to it).
// A program of libuh alone, as a C++ user of uh.h links it.

#include <gtest/gtest.h>

#include <cstring>
#include <functional>
#include <map>
#include <string>

#include "scene_ranges.hpp"
#include "test_paths.hpp"
#include "uh/uh.h"

namespace {

using uh::scene::testing::FieldRange;
using uh::scene::testing::kFieldRanges;

const std::string kStylus = std::string(UH_TEST_DATA_DIR) + "/meshes/stylus.obj";

uh_object_def object_def() {
  uh_object_def def = uh_default_object_def();
  def.name = "bunny";
  def.shape.mesh_path = kStylus.c_str();
  def.shape.spheres = 150;
  def.shape.meters_per_unit = 0.01;
  return def;
}

uh_tool_def tool_def() {
  uh_tool_def def = uh_default_tool_def();
  def.name = "stylus";
  def.shape.mesh_path = kStylus.c_str();
  def.shape.spheres = 150;
  def.shape.meters_per_unit = 0.01;
  return def;
}

// A field set through the C API on a fresh scene; the status of the setter that takes it.
using CApiSetter = std::function<uh_status(uh_scene_id, double)>;

uh_status add_object(uh_scene_id scene, const std::function<void(uh_object_def&)>& edit) {
  uh_object_def def = object_def();
  edit(def);
  return uh_scene_add_object(scene, &def, nullptr);
}

uh_status set_tool(uh_scene_id scene, const std::function<void(uh_tool_def&)>& edit) {
  uh_tool_def def = tool_def();
  edit(def);
  return uh_scene_set_tool(scene, &def);
}

// The table's fields the C API exposes (the others are read from scene files only).
const std::map<std::string, CApiSetter>& capi_setters() {
  static const std::map<std::string, CApiSetter> table{
      {"rates.haptic_hz", [](uh_scene_id s, double v) { return uh_scene_set_rates(s, v, 1000.0); }},
      {"rates.collision_hz", [](uh_scene_id s, double v) { return uh_scene_set_rates(s, 1000.0, v); }},
      {"objects[0].spheres",
       [](uh_scene_id s, double v) {
         return add_object(s, [&](uh_object_def& d) { d.shape.spheres = static_cast<int64_t>(v); });
       }},
      {"objects[0].meters_per_unit",
       [](uh_scene_id s, double v) { return add_object(s, [&](uh_object_def& d) { d.shape.meters_per_unit = v; }); }},
      {"tool.spheres",
       [](uh_scene_id s, double v) {
         return set_tool(s, [&](uh_tool_def& d) { d.shape.spheres = static_cast<int64_t>(v); });
       }},
      {"tool.meters_per_unit",
       [](uh_scene_id s, double v) { return set_tool(s, [&](uh_tool_def& d) { d.shape.meters_per_unit = v; }); }},
      {"tool.force.stiffness", [](uh_scene_id s, double v) { return set_tool(s, [&](uh_tool_def& d) { d.stiffness = v; }); }},
      {"tool.force.damping", [](uh_scene_id s, double v) { return set_tool(s, [&](uh_tool_def& d) { d.damping = v; }); }},
      {"tool.force.damping_full_volume",
       [](uh_scene_id s, double v) { return set_tool(s, [&](uh_tool_def& d) { d.damping_full_volume = v; }); }},
      {"tool.force.mass_kg", [](uh_scene_id s, double v) { return set_tool(s, [&](uh_tool_def& d) { d.mass_kg = v; }); }},
      {"tool.force.max_force_n",
       [](uh_scene_id s, double v) { return set_tool(s, [&](uh_tool_def& d) { d.max_force_n = v; }); }},
      {"tool.force.max_torque_nm",
       [](uh_scene_id s, double v) { return set_tool(s, [&](uh_tool_def& d) { d.max_torque_nm = v; }); }},
      {"tool.workspace.scale",
       [](uh_scene_id s, double v) { return set_tool(s, [&](uh_tool_def& d) { d.workspace_scale = v; }); }},
  };
  return table;
}

TEST(SceneRulesCApi, TheSettersRefuseWhatTheSceneFileRefusesWithItsMessage) {
  int checked = 0;
  for (const FieldRange& f : kFieldRanges) {
    const auto setter = capi_setters().find(f.path);
    if (setter == capi_setters().end()) continue;
    ++checked;
    for (const double value : {uh::scene::testing::below(f), uh::scene::testing::above(f)}) {
      SCOPED_TRACE(fmt::format("{} = {}", f.path, value));
      uh_scene_id scene{0};
      ASSERT_EQ(uh_scene_create("rules", &scene), UH_OK);
      EXPECT_EQ(setter->second(scene, value), UH_ERROR_INVALID_ARGUMENT);
      const std::string error = uh_last_error();
      const std::string expected = uh::scene::testing::range_message(f, value);
      ASSERT_GE(error.size(), expected.size()) << error;
      EXPECT_EQ(error.substr(error.size() - expected.size()), expected) << error;
      uh_scene_destroy(scene);
    }
    for (const double value : {f.min, f.max}) {
      SCOPED_TRACE(fmt::format("{} = {}", f.path, value));
      uh_scene_id scene{0};
      ASSERT_EQ(uh_scene_create("rules", &scene), UH_OK);
      EXPECT_EQ(setter->second(scene, value), UH_OK) << uh_last_error();
      uh_scene_destroy(scene);
    }
  }
  EXPECT_EQ(checked, static_cast<int>(capi_setters().size())) << "every C API setter has its field in the table";
}

}  // namespace
