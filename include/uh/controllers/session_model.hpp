#pragma once
/// \file
/// SessionModel: a scene compiled once into everything a session needs (MuJoCo's model between
/// the description and the data): each object's and tool's tree with its coverage, each object's
/// surface (its .ist's or its mesh's), the combined contact materials, the rates. Immutable plain data: sessions
/// created from one model share it read-only, so a program that compiles once and creates many
/// sessions loads, packs and reads each mesh once.

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "uh/collette/ist_cache.hpp"
#include "uh/collette/mesh_inside.hpp"
#include "uh/collette/sphere_tree.hpp"
#include "uh/controllers/scene.hpp"
#include "uh/core/result.hpp"
#include "uh/forcecomp/material.hpp"
#include "uh/soft/soft_body.hpp"

namespace uh::controllers {

/// A shape resolved: its tree in metres, its coverage and its surface in metres (the proxy rests on
/// it rather than on the packing's grain): the one its .ist holds, else its mesh file's.
struct CompiledShape {
  std::shared_ptr<const collette::SphereTree> tree;
  double coverage = 1.0;  ///< sphere volume / mesh volume, (0, 1]
  /// null for a format 1 .ist alone (or a tree in memory) without a mesh file
  std::shared_ptr<const collette::MeshInside> surface;
  /// How far the packing lies below `surface` at most (the tree's max_gap) [m]; 0 when unknown.
  double surface_gap_m = 0.0;
  /// A deformable object's rest model (`objects[].deformable`): its lattice around the tree's
  /// packing, the held nodes, the leaves embedded; null for a rigid object and for tools.
  std::shared_ptr<const soft::SoftBodyModel> soft;
};

/// A compiled scene. Read-only once compile() returned it; any thread may read it.
struct SessionModel {
  Scene scene;                          ///< the scene, validated (uh::scene::validate)
  std::vector<CompiledShape> objects;   ///< per scene.objects
  std::vector<CompiledShape> tools;     ///< per scene.tools
  /// The contact material of each tool against each object (forcecomp::combine_materials):
  /// materials[tool][object].
  std::vector<std::vector<forcecomp::ContactMaterial>> materials;
};

/// How compile() resolves a scene (aggregate).
struct CompileOptions {
  /// Load a meshed object's surface also when the scene gives its tree beside its mesh file (a
  /// program that preloaded it). HapticSession::create(scene, ...) leaves it off, which keeps what
  /// a preloading caller (`uh explore`) renders on the proxy today, the spheres (issue 24: it
  /// compiles its model next).
  bool surface_beside_given_tree = true;
  /// Give objects their surfaces at all (false: a caller whose proxy rests on the spheres).
  bool surfaces = true;
  /// The packing's progress (what, fraction) while a mesh is packed on first use; calling thread.
  std::function<void(const std::string& what, double fraction)> progress{};
};

/// Validates `scene` and resolves it: trees through `cache` (loaded, or packed and cached on first
/// use; shapes of one packing share one tree; a tree the scene holds is used as it is), every
/// object's surface (the one its .ist holds, else its mesh file's; objects of one shape share it), the materials,
/// and each deformable object's lattice (built here, a progress stage of its own).
/// The model's scene holds each shape's tree and coverage. Errors name the scene's source and the
/// object or tool. Setup only.
Result<std::shared_ptr<const SessionModel>> compile(const Scene& scene, collette::IstCache& cache,
                                                    const CompileOptions& options = {});

}  // namespace uh::controllers
