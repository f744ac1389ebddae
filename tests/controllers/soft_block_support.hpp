#pragma once
// scenes/soft_block.json as the soft-object tests press it (issue 26): the ball going down to a
// depth below the block's top face and staying there.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "test_paths.hpp"
#include "uh/controllers/scene.hpp"

namespace uh::controllers::testing {

inline const std::filesystem::path kSoftBlockFile = std::filesystem::path(UH_TEST_DATA_DIR).parent_path() / "scenes" / "soft_block.json";

enum class Path { kProxy, kPenalty };

// the committed scene, the ball going down to `depth_m` below the top face in `duration_s` (from
// 12 mm above the top face: its centre 2 mm above) and staying; through the proxy (the scene's
// default) or on the penalty path
inline Scene soft_block(double depth_m, bool soft = true, Path path = Path::kProxy, double duration_s = 0.5) {
  std::ifstream in(kSoftBlockFile);
  nlohmann::json j = nlohmann::json::parse(in);
  j["tool"]["device"]["config"]["end"] = {0.0, 0.0, 0.01 - depth_m};  // the ball's centre: its radius above
  j["tool"]["device"]["config"]["duration_s"] = duration_s;
  j["tool"]["device"]["config"]["bounce"] = false;
  j["objects"][0]["spheres"] = 1500;  // quicker to pack, as deep
  if (!soft) j["objects"][0].erase("deformable");
  if (path == Path::kPenalty) j["force"]["proxy"]["enabled"] = false;
  auto scene = parse_scene(j.dump(), kSoftBlockFile.string(), kSoftBlockFile.parent_path());
  EXPECT_TRUE(scene.has_value()) << scene.error().message;
  return *scene;
}

// the committed scene pressed by a simulated hand that reacts to the force (sim-hand, as
// scenes/bunny_hand_press.json's): it pulls the ball from 2 mm above the top face towards 2 cm
// below it and back, twice in 4 s, through the proxy, whose spring is the coupling's clamp for a
// device damping of `told_damping` (the hand device has 1 N s/m)
inline Scene soft_block_hand_press(double told_damping) {
  std::ifstream in(kSoftBlockFile);
  nlohmann::json j = nlohmann::json::parse(in);
  j["seconds"] = 4.0;
  j["objects"][0]["spheres"] = 1500;
  j["tool"]["force"]["stiffness"] = 1e6;  // a hard material: the spring rendered is the clamp
  j["tool"]["device"] = nlohmann::json::parse(R"({"driver": "sim-hand", "config": {
      "target_start": [0.0, 0.0, 0.012], "target_end": [0.0, 0.0, -0.01], "duration_s": 1.0, "bounce": true,
      "handle_mass_kg": 0.1, "hand_stiffness": 300, "hand_damping": 3.0, "device_damping": 1.0,
      "substeps": 20, "dof_actuated": 3, "max_force_n": 8}})");
  j["force"]["coupling"] = {{"stiffness", 1e6}, {"damping", 0.0}, {"device_damping", told_damping},
                            {"passivity_margin", 0.9}};
  auto scene = parse_scene(j.dump(), kSoftBlockFile.string(), kSoftBlockFile.parent_path());
  EXPECT_TRUE(scene.has_value()) << scene.error().message;
  return *scene;
}

}  // namespace uh::controllers::testing
