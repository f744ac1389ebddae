#pragma once
/// \file
/// Loading and validating triangle meshes (OBJ, STL, PLY, OFF and every other format assimp reads).

#include <filesystem>

#include "uh/collette/triangle_mesh.hpp"
#include "uh/core/result.hpp"

namespace uh::collette {

/// How strictly load_mesh() / validate_mesh() treat a mesh (Box2D-style options aggregate).
struct MeshLoadOptions {
  /// Vertices closer than weld_tolerance * (bounding-box diagonal) are merged. 0 merges only
  /// bit-identical positions. STL files are unindexed, so welding is what makes them a mesh.
  double weld_tolerance = 1e-7;
  /// Accept meshes with at most max_open_boundary_edges boundary edges. The mesh is then kept as
  /// is, report.assumed_open is set and inside tests must use the generalised winding number
  /// (MeshInside does). Non-manifold edges and inconsistent orientation are still errors.
  bool allow_open = false;
  std::int64_t max_open_boundary_edges = 1000;
  /// Drop degenerate (zero-area or repeated-vertex) triangles instead of rejecting the mesh.
  bool drop_degenerate = false;
  /// A triangle is degenerate when twice its area is below this times the squared bbox diagonal.
  double degenerate_area_tolerance = 1e-14;
};

/// Reads a mesh file, welds vertices, validates it and fixes an inverted winding.
///
/// Errors name the file and say what is wrong, e.g. "teapot.obj: mesh is not closed: 64 boundary
/// edges, 0 non-manifold edges, 0 degenerate faces (a closed 2-manifold mesh is required; ...)".
/// Missing, unreadable and empty files are errors too. All meshes in the file are merged. Setup
/// code only (allocates, reads files); any thread; not real-time safe.
Result<TriangleMesh> load_mesh(const std::filesystem::path& path, const MeshLoadOptions& options = {});

/// Welds, validates and orients an in-memory mesh the same way load_mesh() does (used by
/// load_mesh() and by code that builds meshes itself). `mesh.source_name` names it in messages.
/// On success mesh.report holds the counts. Not real-time safe.
Result<TriangleMesh> validate_mesh(TriangleMesh mesh, const MeshLoadOptions& options = {});

}  // namespace uh::collette
