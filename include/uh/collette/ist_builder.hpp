#pragma once
/// \file
/// From a mesh file to an Inner Sphere Tree asset in one call: load and validate the mesh, pack it
/// with spheres, build the hierarchy and fill the metadata. Used by `uh ist build` and by scenes
/// that build .ist files on first use.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>

#include "uh/collette/ist_file.hpp"
#include "uh/collette/mesh_import.hpp"
#include "uh/collette/mesh_report.hpp"
#include "uh/collette/sphere_packing.hpp"
#include "uh/collette/sphere_tree_builder.hpp"
#include "uh/core/result.hpp"

namespace uh::collette {

/// Settings of build_ist_asset() (aggregate; designated initialisers).
struct IstBuildOptions {
  std::int64_t sphere_count = 10000;                ///< target number of leaf spheres
  double voxel_size = 0.0;                          ///< distance-field voxel [mesh units]; 0 = automatic
  double max_radius = 0.0;                          ///< largest sphere radius [mesh units]; 0 = unbounded
  double meters_per_unit = 1.0;                     ///< stored in the asset: length of one mesh unit [m]
  MeshLoadOptions mesh{};                           ///< import and validation settings
  SphereTreeBuildOptions tree{};                    ///< hierarchy settings
  std::function<void(double fraction)> progress{};  ///< packing progress in [0, 1], calling thread
};

/// The asset and what was found on the way.
struct IstBuildResult {
  IstAsset asset;
  MeshReport mesh{};          ///< validation counts and what was fixed or assumed
  PackingReport packing{};    ///< coverage, gap, timing of the packing
  double tree_seconds = 0.0;  ///< time to build the hierarchy [s]
};

/// Loads `mesh_path` (with options.mesh), packs it and builds the tree; the asset keeps the mesh
/// as its surface (ist_surface_of). Errors name the file and
/// say what is wrong. Nothing is written to disk. Not real-time safe; any thread.
Result<IstBuildResult> build_ist_asset(const std::filesystem::path& mesh_path,
                                       const IstBuildOptions& options = {});

/// Packs an already loaded and validated mesh (load_mesh() / validate_mesh(); options.mesh is
/// not used) and builds the tree, for callers that look at the MeshReport before packing.
/// `source_mesh_hash` goes into the metadata (hash_file() of the mesh file, 0 if unknown);
/// messages name mesh.source_name. Not real-time safe; any thread.
Result<IstBuildResult> build_ist_asset(const TriangleMesh& mesh, std::uint64_t source_mesh_hash,
                                       const IstBuildOptions& options = {});

/// The surface an asset keeps of the mesh it was packed from (IstAsset::surface): the validated
/// mesh as it is, or none for a mesh accepted open (its holes are capped only inside the packing).
std::optional<TriangleMesh> ist_surface_of(const TriangleMesh& mesh);

/// A copy of `tree` with every length multiplied by `factor` (> 0) and every volume by factor^3,
/// e.g. to bring a tree in mesh units into metres. Not real-time safe.
SphereTree scale_sphere_tree(const SphereTree& tree, double factor);

/// `asset` in metres, one of its units being `meters_per_unit` (> 0): the tree (scale_sphere_tree),
/// mesh volume, max gap and surface scaled, meters_per_unit 1. Not real-time safe.
IstAsset ist_asset_in_metres(const IstAsset& asset, double meters_per_unit);

/// FNV-1a hash of a file's bytes (IstMetadata::source_mesh_hash); an error if it cannot be read.
Result<std::uint64_t> hash_file(const std::filesystem::path& path);

}  // namespace uh::collette
