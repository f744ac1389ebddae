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

// the committed scene, the ball going down to `depth_m` below the top face in 0.5 s and staying;
// through the proxy (the scene's default) or on the penalty path
inline Scene soft_block(double depth_m, bool soft = true, Path path = Path::kProxy) {
  std::ifstream in(kSoftBlockFile);
  nlohmann::json j = nlohmann::json::parse(in);
  j["tool"]["device"]["config"]["end"] = {0.0, 0.0, 0.01 - depth_m};  // the ball's centre: its radius above
  j["tool"]["device"]["config"]["duration_s"] = 0.5;
  j["tool"]["device"]["config"]["bounce"] = false;
  j["objects"][0]["spheres"] = 1500;  // quicker to pack, as deep
  if (!soft) j["objects"][0].erase("deformable");
  if (path == Path::kPenalty) j["force"]["proxy"]["enabled"] = false;
  auto scene = parse_scene(j.dump(), kSoftBlockFile.string(), kSoftBlockFile.parent_path());
  EXPECT_TRUE(scene.has_value()) << scene.error().message;
  return *scene;
}

}  // namespace uh::controllers::testing
