#pragma once
// A small scene over the committed meshes (few spheres, so that tests stay fast under sanitizers),
// written as JSON text like the files in scenes/.

#include <filesystem>
#include <string>

#include <fmt/format.h>

namespace uh::controllers::testing {

inline std::filesystem::path test_assets() { return std::filesystem::path(UH_TEST_DATA_DIR); }

/// A fresh, empty cache directory for .ist builds.
inline std::filesystem::path fresh_cache(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / fmt::format("uh-controllers-test-{}-{}", name, ::getpid());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

/// The stylus goes down from above the bunny into it and back (sim-line), 3-DOF or 6-DOF.
inline std::string small_scene_json(bool multi_rate = true, bool coupling = false, double collision_hz = 1000) {
  return fmt::format(R"({{
  "name": "small-test",
  "rates": {{ "haptic_hz": 1000, "collision_hz": {collision_hz} }},
  "seconds": 1.0,
  "objects": [{{
    "name": "bunny",
    "mesh": "meshes/bunny_npm_3674.obj",
    "meters_per_unit": 0.01,
    "spheres": 600,
    "pose": {{ "position": [0, 0, 0], "rotation": [0.70710678, 0.70710678, 0, 0] }}
  }}],
  "tool": {{
    "name": "stylus",
    "mesh": "meshes/stylus.obj",
    "meters_per_unit": 0.01,
    "spheres": 150,
    "force": {{ "mode": "6dof", "force_scale": 8.0e6, "damping": 1.0, "center_of_mass": [0, 0, 0.025],
               "max_force_n": 6.0, "max_torque_nm": 0.3 }},
    "device": {{ "driver": "sim-line",
                "config": {{ "start": [0.0, 0.0, 0.10], "end": [0.0, 0.0, 0.045], "duration_s": 0.5, "bounce": true,
                            "dof_actuated": 6, "max_force_n": 6 }} }}
  }},
  "watch": ["bunny"],
  "force": {{ "multi_rate": {multi_rate}, "coupling": {{ "enabled": {coupling}, "stiffness": 800, "damping": 0.2 }} }}
}})",
                     fmt::arg("collision_hz", collision_hz), fmt::arg("multi_rate", multi_rate ? "true" : "false"),
                     fmt::arg("coupling", coupling ? "true" : "false"));
}

}  // namespace uh::controllers::testing
