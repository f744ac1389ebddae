#pragma once
/// \file
/// IstCache: where built .ist files are kept, and the load-or-build of a mesh's packing through
/// them, so that a mesh is packed once per sphere count, radius bound and tree builder version.
/// Trees are returned in metres and shared: one cache hands the same tree to every caller that
/// asks for the same shape (the objects of a room that repeat a mesh, the sessions of one model).

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <tuple>

#include "uh/collette/mesh_inside.hpp"
#include "uh/collette/sphere_tree.hpp"
#include "uh/core/result.hpp"

namespace uh::collette {

/// A tree in metres with its packing's coverage (sphere volume / mesh volume, (0, 1]).
struct CachedTree {
  std::shared_ptr<const SphereTree> tree;
  double coverage = 1.0;
  /// The packing's largest gap below the mesh surface (IstMetadata::max_gap) [m]; 0 when unknown.
  double max_gap_m = 0.0;
  /// The surface the spheres were packed in (IstAsset::surface), in metres in the tree's frame;
  /// null when the .ist holds none (a version 1 file, a mesh packed open).
  std::shared_ptr<const MeshInside> surface{};
};

/// What a mesh is packed with (the key of its cached build, with the mesh file's hash).
struct MeshPacking {
  std::int64_t spheres = 10000;  ///< leaf spheres
  double max_radius_m = 0.0;     ///< largest sphere radius [m]; 0 = unbounded
  double meters_per_unit = 1.0;  ///< length of one mesh unit [m]
};

/// The .ist cache of a folder. Setup only (files are read, hashed, packed and written); one
/// thread at a time.
class IstCache {
 public:
  /// `dir` is created on the first build; empty: default_dir().
  explicit IstCache(std::filesystem::path dir = {});

  /// $UH_CACHE_DIR, else $XDG_CACHE_HOME/unrealhaptics, else (Windows)
  /// %LOCALAPPDATA%\unrealhaptics\cache, else ~/.cache/unrealhaptics, else a folder in the system
  /// temp directory.
  static std::filesystem::path default_dir();

  const std::filesystem::path& dir() const { return dir_; }

  using Progress = std::function<void(const std::string& what, double fraction)>;

  /// The packing of `mesh` in metres with its surface: the cached build (keyed by the mesh file's
  /// hash, the sphere count, the radius bound in mesh units and kSphereTreeBuilderVersion), else
  /// packed now and cached (only the cache file is replaced when it is absent, unreadable or
  /// stale). A cached file without a surface (format version 1) gets the mesh's, written back
  /// without packing again. `progress` gets the packing's progress when a build is needed.
  Result<CachedTree> mesh_tree(const std::filesystem::path& mesh, const MeshPacking& packing,
                               const Progress& progress = {});

  /// A prebuilt .ist file's tree in metres (its own meters_per_unit) with its coverage and, when
  /// the file holds one, its surface.
  Result<CachedTree> ist_tree(const std::filesystem::path& ist);

 private:
  using Key = std::tuple<std::string, std::int64_t, double, double>;
  std::filesystem::path dir_;
  std::map<Key, CachedTree> loaded_;  // trees handed out already, shared by the next caller
};

}  // namespace uh::collette
