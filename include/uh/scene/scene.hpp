#pragma once
/// \file
/// A scene: the objects, the tools and their devices, the watched pairs, rates and safety limits
/// of a haptic session, as plain data a user edits (MuJoCo's description). Read from JSON files
/// (scenes/*.json; the CLI, the tests and the benchmarks use the same files; format:
/// docs/scenes.md), built by the C API or edited by `uh serve`; uh::scene::validate() checks every
/// field in one place; uh::controllers compiles it into the model a session runs.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "uh/core/math.hpp"
#include "uh/core/result.hpp"
#include "uh/forcecomp/force_params.hpp"
#include "uh/forcecomp/material.hpp"
#include "uh/haptico/device_config.hpp"
#include "uh/haptico/force_limiter.hpp"
#include "uh/scene/force_options.hpp"
#include "uh/scene/workspace_mapping.hpp"

namespace uh::collette {
class MeshInside;
class SphereTree;
}  // namespace uh::collette

namespace uh::scene {

/// Where an object's Inner Sphere Tree comes from: a mesh (packed on first use, cached), a .ist
/// file, or a tree already in memory (built by the program, e.g. through the C API).
struct SceneShape {
  std::filesystem::path mesh{};      ///< mesh file (absolute after loading), or empty when `ist` or `tree` is set
  std::filesystem::path ist{};       ///< prebuilt .ist file, or empty
  std::shared_ptr<const collette::SphereTree> tree{};  ///< a tree in metres, shared; used as it is when set
  /// With `tree`: its packing's coverage (sphere volume / mesh volume, (0, 1]), which calibrates the
  /// gradient force law; 1 when unknown. Meshes and .ist files bring their own.
  double coverage = 1.0;
  /// With `tree`: the surface its spheres were packed in, in metres in the tree's frame (a tree
  /// loaded from a format 2 .ist or built from a mesh), which the proxy rests on; null: none, the
  /// proxy rests on the spheres. Meshes and .ist files bring their own.
  std::shared_ptr<const collette::MeshInside> surface{};
  /// With `surface`: how far the packing lies below it at most [m] (the .ist's max gap); 0 unknown.
  double surface_gap_m = 0.0;
  std::int64_t spheres = 10000;      ///< leaf spheres when packing the mesh
  /// Largest sphere radius when packing the mesh [m]; 0 = unbounded (collette::PackingOptions::max_radius).
  double max_sphere_radius = 0.0;
  double meters_per_unit = 1.0;      ///< length of one mesh unit [m]; the session works in metres
};

/// `objects[].deformable`: a soft object, simulated on its own thread (issue 26; docs/deformables.md,
/// docs/scenes.md "Deformable objects"). Its volume is a lattice of tetrahedra around its mesh.
struct SceneDeformable {
  double young_modulus_pa = 5.0e4;  ///< E [Pa]
  double poisson_ratio = 0.45;      ///< nu
  double density_kg_m3 = 1000.0;    ///< rho [kg/m^3]
  double damping = 0.01;            ///< stiffness-proportional (Rayleigh) damping [s]: damps deformation only
  std::int64_t tetrahedra = 0;      ///< about this many elements; 0 = chosen from the object's size
  double rate_hz = 200.0;           ///< the simulation thread's steps a second [Hz] (fixed steps of 1/rate_hz)
  /// `fixed.box`: mesh vertices and tet nodes inside it [m], object frame, are held in place.
  struct Box {
    Vec3 min{};
    Vec3 max{};
  };
  std::optional<Box> fixed_box{};
};

/// A static object of the scene.
struct SceneObject {
  std::string name;
  SceneShape shape;
  Pose pose{};                       ///< world_from_object [m]
  /// `objects[].material`: what the surface feels like (stiffness, damping, friction, texture);
  /// nothing set = as the tool's force parameters say (docs/scenes.md, "Materials").
  forcecomp::Material material{};
  /// `objects[].deformable`: set for a soft object; a rigid one has none.
  std::optional<SceneDeformable> deformable{};
};

/// The device a tool is bound to: a registered driver name and its settings.
struct SceneDevice {
  std::string driver = "sim-line";
  haptico::DeviceConfig config;
};

/// A tool: a shape moved by its own device, with its force component. A scene holds one or more.
struct SceneTool {
  std::string name = "tool";
  SceneShape shape;
  forcecomp::ForceParams force{};
  /// `tool.material`: the tool's own surface, combined with each object's (forcecomp::combine_materials).
  forcecomp::Material material{};
  forcecomp::ForceMode mode = forcecomp::ForceMode::k6Dof;
  SceneDevice device;
  WorkspaceMapping workspace{};
};

/// A whole session description.
struct Scene {
  std::string name;                    ///< for messages and reports
  std::string source;                  ///< file the scene came from ("<embedded>" for the default)
  std::vector<SceneObject> objects;
  /// The tools, each bound to its own device (`tool`, or `tools` for several: two hands, two
  /// users); never empty. Each touches the objects; tools pass through each other.
  std::vector<SceneTool> tools{1};
  std::vector<std::string> watch;      ///< object names watched against every tool
  double haptic_hz = 1000.0;           ///< haptic thread rate [Hz]
  double collision_hz = 1000.0;        ///< collision thread rate [Hz]; 0 = free-running
  double seconds = 10.0;               ///< default session length [s]
  double contact_margin = 0.001;       ///< collision pairs delivered this far [m] before they touch (multi-rate)
  double coherence_skin = 0.0;         ///< frame-to-frame coherence skin of the volume query [m]; 0 = off
  ForceControllerOptions force{};      ///< multi-rate, watchdog, coupling
  /// The session's safety limits (`force.safety.max_force_n`, `max_torque_nm`); the session's
  /// limit chain applies the smallest of these, the tool's (`tool.force`) and the device's.
  haptico::WrenchLimit safety_limits{.max_force_n = 10.0, .max_torque_nm = 0.5};
  /// `force.safety.max_force_rate_n_per_s`, `max_torque_rate_nm_per_s`: the largest change of the
  /// command per second (per tick: divided by the haptic rate); zero is always sent at once.
  haptico::ForceRateLimit rate_limit{};

  /// The first tool (the only one in one-tool scenes).
  SceneTool& tool() { return tools.front(); }
  const SceneTool& tool() const { return tools.front(); }
};

/// Reads a scene file. Errors name the file, the field (as a JSON path such as
/// `tool.device.driver`) and what is expected; unknown fields are errors too (typos).
/// Relative mesh and .ist paths are resolved against the scene file's directory.
/// The file must be a regular file of at most kMaxSceneFileBytes (uh/core/regular_file.hpp); a
/// mesh or .ist it names must be a regular file too.
Result<Scene> load_scene(const std::filesystem::path& path);

/// The text of a scene file, read as load_scene() reads it (a regular file, size-limited).
Result<std::string> read_scene_file(const std::filesystem::path& path);

/// Parses scene JSON text; `source` names it in messages, `base_dir` resolves relative paths.
Result<Scene> parse_scene(std::string_view json_text, const std::string& source, const std::filesystem::path& base_dir);

/// The scene as a scene file's text, which load_scene() reads back to the same scene: every field
/// written (defaults too), materials inline, mesh and .ist paths as the scene holds them (absolute
/// after load_scene()). Refuses a scene validate() refuses, and a shape whose tree is held only
/// in memory (no file to name).
Result<std::string> write_scene(const Scene& scene);

/// Reads a device's settings from a JSON object (numbers, strings, booleans, [x, y, z]) as a
/// scene's `tool.device.config` (or `tools[i].device.config`) is read; a relative `file` resolves against
/// `base_dir`. Errors name `source` and the key.
Result<haptico::DeviceConfig> parse_device_config(std::string_view json_text, const std::string& source,
                                                  const std::filesystem::path& base_dir);

/// The embedded default scene: the bunny explored by a stylus on a raster sweep into deep contact.
/// Its meshes are written into `cache_dir` on first use.
Result<Scene> default_scene(const std::filesystem::path& cache_dir);

/// Writes the embedded default scene file and its meshes into `cache_dir` (unless they are there
/// already) and returns the scene file's path, for callers that edit the scene as JSON.
Result<std::filesystem::path> write_default_scene(const std::filesystem::path& cache_dir);

}  // namespace uh::scene
