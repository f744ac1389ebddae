#pragma once
// A small scene over the committed meshes (few spheres, so that tests stay fast under sanitizers),
// written as JSON text like the files in scenes/.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "test_paths.hpp"
#include "uh/core/csv_reader.hpp"
#include "uh/core/math.hpp"

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
    "force": {{ "mode": "6dof", "stiffness": 1.6e4, "damping": 1.0, "center_of_mass": [0, 0, 0.025],
               "max_force_n": 6.0, "max_torque_nm": 0.3 }},
    "device": {{ "driver": "sim-line",
                "config": {{ "start": [0.0, 0.0, 0.10], "end": [0.0, 0.0, 0.045], "duration_s": 0.5, "bounce": true,
                            "dof_actuated": 6, "max_force_n": 6 }} }}
  }},
  "watch": ["bunny"],
  "force": {{ "multi_rate": {multi_rate}, "coupling": {{ "enabled": {coupling}, "stiffness": 800, "damping": 0.2 }} }}
}})",
                     fmt::arg("collision_hz", collision_hz),
                     fmt::arg("multi_rate", multi_rate ? "true" : "false"),
                     fmt::arg("coupling", coupling ? "true" : "false"));
}

/// Two hands: the bunny and a ball beside it (15 cm apart), a stylus on its own sim-line device
/// pressing into each ("left" into the bunny, "right" into the ball, 6-DOF and 3-DOF).
/// `tools` picks which: "both" (the list `tools`), "left" or "right" (that one alone, as `tool`):
/// the one-tool sessions are the references of the two-tool one.
inline std::string two_hands_scene_json(const std::string& tools = "both", const std::string& extra = "") {
  const std::string left = R"({
    "name": "left", "mesh": "meshes/stylus.obj", "meters_per_unit": 0.01, "spheres": 150,
    "force": { "mode": "6dof", "stiffness": 1.6e4, "damping": 1.0, "center_of_mass": [0, 0, 0.025],
               "max_force_n": 6.0, "max_torque_nm": 0.3 },
    "device": { "driver": "sim-line",
                "config": { "start": [0.0, 0.0, 0.10], "end": [0.0, 0.0, 0.045], "duration_s": 0.5, "bounce": true,
                            "dof_actuated": 6, "max_force_n": 6 } } })";
  const std::string right = R"({
    "name": "right", "mesh": "meshes/stylus.obj", "meters_per_unit": 0.01, "spheres": 150,
    "force": { "mode": "3dof", "stiffness": 1.0e4, "damping": 0.5, "center_of_mass": [0, 0, 0.025],
               "max_force_n": 4.0 },
    "device": { "driver": "sim-line",
                "config": { "start": [0.15, 0.0, 0.10], "end": [0.15, 0.0, 0.048], "duration_s": 0.4, "bounce": true,
                            "dof_actuated": 3, "max_force_n": 4 } } })";
  const std::string tool_part = tools == "both"   ? fmt::format(R"("tools": [{}, {}])", left, right)
                                : tools == "left" ? fmt::format(R"("tool": {})", left)
                                                  : fmt::format(R"("tool": {})", right);
  return fmt::format(R"({{
  "name": "two-hands-test",
  "rates": {{ "haptic_hz": 1000, "collision_hz": 1000 }},
  "seconds": 1.0,
  "objects": [{{
    "name": "bunny", "mesh": "meshes/bunny_npm_3674.obj", "meters_per_unit": 0.01, "spheres": 600,
    "pose": {{ "position": [0, 0, 0], "rotation": [0.70710678, 0.70710678, 0, 0] }}
  }}, {{
    "name": "ball", "mesh": "meshes/ball.obj", "meters_per_unit": 0.03, "spheres": 200,
    "pose": {{ "position": [0.15, 0, 0.03], "rotation": [1, 0, 0, 0] }}
  }}],
  {tool_part}{extra}
}})",
                     fmt::arg("tool_part", tool_part), fmt::arg("extra", extra));
}

/// `text` with the first `from` replaced by `to`; a test failure if `from` is not there.
inline std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "not in the scene: " << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

/// The small scene with force limits [N] of the tool (`tool.force`), of the session
/// (`force.safety`) and of the device (`tool.device.config`), and a force rate limit [N/s].
inline std::string small_scene_with_limits(double tool_n, double safety_n, double device_n,
                                           double rate_n_per_s = 1000.0, double collision_hz = 1000) {
  std::string s = small_scene_json(true, false, collision_hz);
  s = replaced(s, R"("max_force_n": 6.0, "max_torque_nm": 0.3)",
               fmt::format(R"("max_force_n": {}, "max_torque_nm": 0.3)", tool_n));
  s = replaced(s, R"("dof_actuated": 6, "max_force_n": 6)",
               fmt::format(R"("dof_actuated": 6, "max_force_n": {})", device_n));
  return replaced(
      s, R"("force": { "multi_rate")",
      fmt::format(
          R"("force": {{ "safety": {{ "max_force_n": {}, "max_force_rate_n_per_s": {} }}, "multi_rate")",
          safety_n, rate_n_per_s));
}

/// The rows of a trace CSV (haptico::write_trace_header / write_trace_row) by column name.
struct TraceTable {
  std::vector<std::string> names;
  std::vector<std::vector<double>> rows;

  int column(const std::string& name) const {
    for (std::size_t i = 0; i < names.size(); ++i)
      if (names[i] == name) return static_cast<int>(i);
    ADD_FAILURE() << "no trace column " << name;
    return 0;
  }
  /// The sent force of row `i` [N].
  Vec3 force(std::size_t i) const {
    const auto& r = rows[i];
    return {r[static_cast<std::size_t>(column("fx"))], r[static_cast<std::size_t>(column("fy"))],
            r[static_cast<std::size_t>(column("fz"))]};
  }
  std::uint32_t flags(std::size_t i) const {
    return static_cast<std::uint32_t>(rows[i][static_cast<std::size_t>(column("flags"))]);
  }
};

// read with the project's CSV reader; a malformed trace fails the test
inline TraceTable parse_trace(const std::string& csv) {
  TraceTable t;
  std::istringstream in(csv);
  CsvReader reader(in, "trace.csv");
  const Status header = reader.read_header();
  EXPECT_TRUE(header) << header.error().message;
  if (!header) return t;
  t.names = reader.columns();
  while (true) {
    auto more = reader.next_row();
    EXPECT_TRUE(more) << more.error().message;
    if (!more || !*more) return t;
    std::vector<double>& row = t.rows.emplace_back();
    for (std::size_t c = 0; c < t.names.size(); ++c) {
      auto number = reader.number(c);
      EXPECT_TRUE(number) << number.error().message;
      row.push_back(number ? *number : 0.0);
    }
  }
}

}  // namespace uh::controllers::testing
