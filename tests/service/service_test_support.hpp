#pragma once
// Shared by the service tests: a small scene file over the committed meshes (few spheres, so the
// tests stay fast under sanitizers) and scratch folders.

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <fmt/format.h>
#include "test_paths.hpp"

namespace uh::service::testing {

inline std::filesystem::path assets() { return std::filesystem::path(UH_TEST_DATA_DIR); }

/// A fresh scratch folder.
inline std::filesystem::path scratch(const std::string& name) {
  const auto dir =
      std::filesystem::temp_directory_path() / fmt::format("uh-service-test-{}-{}", name, ::getpid());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

/// Writes a scene into `dir`: the stylus goes down into the bunny and back (sim-line, 0.5 s). Its
/// meshes are copied into `dir`/meshes (a server reads only from its root folder and its cache).
inline std::filesystem::path write_small_scene(const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir / "meshes");
  for (const char* mesh : {"bunny_npm_3674.obj", "stylus.obj"})
    std::filesystem::copy_file(assets() / "meshes" / mesh, dir / "meshes" / mesh,
                               std::filesystem::copy_options::overwrite_existing);
  const std::string text =
      fmt::format(R"({{
  "name": "small-service-test",
  "rates": {{ "haptic_hz": 1000, "collision_hz": 500 }},
  "objects": [{{ "name": "bunny", "mesh": "{mesh}", "meters_per_unit": 0.01, "spheres": 400,
                "pose": {{ "position": [0, 0, 0], "rotation": [0.70710678, 0.70710678, 0, 0] }} }}],
  "tool": {{
    "name": "stylus", "mesh": "{stylus}", "meters_per_unit": 0.01, "spheres": 120,
    "force": {{ "mode": "6dof", "stiffness": 1.6e4, "damping": 1.0, "max_force_n": 6.0, "max_torque_nm": 0.3 }},
    "device": {{ "driver": "sim-line",
                "config": {{ "start": [0.0, 0.0, 0.10], "end": [0.0, 0.0, 0.045], "duration_s": 0.5, "bounce": true }} }}
  }}
}})",
                  fmt::arg("mesh", "meshes/bunny_npm_3674.obj"), fmt::arg("stylus", "meshes/stylus.obj"));
  const auto path = dir / "small.json";
  std::ofstream(path) << text;
  return path;
}

}  // namespace uh::service::testing
