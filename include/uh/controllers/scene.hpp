#pragma once
/// \file
/// Scenes as the controllers use them: the description (uh/scene/scene.hpp, checked by
/// uh/scene/validate.hpp) under its controllers names, and the loading of a shape's tree and mesh
/// surface for a session.

#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include "uh/collette/ist_cache.hpp"
#include "uh/collette/mesh_inside.hpp"
#include "uh/collette/sphere_tree.hpp"
#include "uh/controllers/force_controller.hpp"
#include "uh/controllers/workspace_mapping.hpp"
#include "uh/core/result.hpp"
#include "uh/scene/scene.hpp"
#include "uh/scene/validate.hpp"
#include "uh/soft/surface_mesh.hpp"

namespace uh::controllers {

using uh::scene::default_scene;
using uh::scene::load_scene;
using uh::scene::parse_device_config;
using uh::scene::parse_scene;
using uh::scene::read_scene_file;
using uh::scene::Scene;
using uh::scene::SceneDevice;
using uh::scene::SceneObject;
using uh::scene::SceneShape;
using uh::scene::SceneTool;
using uh::scene::write_default_scene;

/// Where built .ist files are cached: collette::IstCache::default_dir().
std::filesystem::path default_cache_dir();

/// A shape's tree in metres with its packing's coverage (sphere volume / mesh volume, (0, 1]).
using ShapeTree = collette::CachedTree;

/// The shape's tree in metres: the tree in memory as it is (with SceneShape::coverage and
/// SceneShape::surface), else the
/// .ist file's or the mesh's packing through `cache` (collette::IstCache: built and cached on
/// first use; a cache shares one tree between the shapes that ask for the same). Setup only.
Result<ShapeTree> tree_of(const SceneShape& shape, collette::IstCache& cache,
                          const collette::IstCache::Progress& progress = {});

/// tree_of() through a cache of `cache_dir` made for this call, for callers that load one tree.
Result<ShapeTree> load_shape_tree(
    const SceneShape& shape, const std::filesystem::path& cache_dir,
    const std::function<void(const std::string& what, double fraction)>& progress = {});

/// The shape's mesh surface in metres, for exact nearest-point queries (the proxy rests on it rather
/// than on the packing's grain); null when the shape has no mesh file (a .ist file; a tree in memory
/// without the mesh it was packed from).
/// The mesh is read and validated as for packing. Setup only.
Result<std::shared_ptr<const collette::MeshInside>> load_shape_surface(const SceneShape& shape);

/// A soft object's drawn surface: the shape's mesh in metres, refined (soft::refine_surface); its
/// vertices are those a session deforms and `uh serve` draws. Empty for a shape with no mesh file.
/// Setup only.
Result<soft::SurfaceMesh> load_soft_surface(const SceneShape& shape);

}  // namespace uh::controllers
