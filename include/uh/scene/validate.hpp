#pragma once
/// \file
/// The one check of a scene's fields: every range and every rule between fields that
/// docs/scenes.md states, applied alike to a scene read from a file (parse_scene), built through
/// the C API, edited by `uh serve` or handed to a session. No other place checks a scene field.

#include <cstddef>
#include <string>

#include "uh/core/result.hpp"
#include "uh/scene/scene.hpp"

namespace uh::scene {

/// Checks the whole scene: each object, tool, material, rate, limit and option in its documented
/// range, the rules between fields (a friction's dynamic coefficient at most its static one, the
/// proxy's smoothing at most a quarter of its step, the proxy or the coupling, a material
/// stiffness only under the gradient law), unique names, watched names that exist, at least one
/// object and one tool, and the mesh and .ist files present as regular files. The error
/// (ErrorKind::kInvalid) names the field as the scene file spells it:
/// `field 'objects[2].material.friction.static': expected a number in [0, 10], got 11`.
/// Setup only (it stats the files).
Status validate(const Scene& scene);

/// The parts of validate(), for a caller that builds a scene piece by piece (the C API's
/// setters): each checks what validate() checks of that piece, and names fields under `path`
/// (`objects[i]`, `tool` or `tools[i]`).
Status validate_shape(const SceneShape& shape, const std::string& path);
Status validate_object(const SceneObject& object, const std::string& path);
Status validate_tool(const SceneTool& tool, const std::string& path);
/// A material at `path` (its own path, e.g. `objects[0].material` or `materials.wood`).
Status validate_material(const forcecomp::Material& material, const std::string& path);
/// The rates (`rates.haptic_hz` in [1, 10000], `rates.collision_hz` in [0, 10000], 0 = free-running).
Status validate_rates(double haptic_hz, double collision_hz);

/// Where tool `index` sits in a scene file: `tool` when the scene has one, else `tools[index]`.
std::string tool_path(const Scene& scene, std::size_t index);

}  // namespace uh::scene
