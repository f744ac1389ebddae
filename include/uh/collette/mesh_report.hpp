#pragma once
/// \file
/// MeshReport: the counts that mesh validation found (plain, trivially copyable).

#include <cstdint>
#include <type_traits>

namespace uh::collette {

/// What validate_mesh() / load_mesh() found in a mesh, and what it fixed or assumed.
/// Edges are undirected vertex pairs after welding.
struct MeshReport {
  std::int64_t input_vertex_count = 0;  ///< vertices as read from the file (STL: 3 per triangle)
  std::int64_t vertex_count = 0;        ///< vertices after welding and dropping unused ones
  std::int64_t triangle_count = 0;      ///< triangles kept (after any repair)
  std::int64_t welded_vertices = 0;     ///< input vertices merged into another one
  std::int64_t boundary_edges = 0;      ///< edges used by exactly one triangle (holes)
  std::int64_t non_manifold_edges = 0;  ///< edges used by three or more triangles
  std::int64_t degenerate_faces = 0;    ///< triangles with repeated vertices or (near) zero area
                                        ///< (dropped when MeshLoadOptions::repair)
  std::int64_t duplicate_faces = 0;     ///< triangles on the same three vertices as another one
                                        ///< (dropped when MeshLoadOptions::repair)
  bool repaired = false;                ///< degenerate or duplicate faces were dropped
  std::int64_t inconsistent_edges = 0;  ///< manifold edges whose two triangles traverse it the same way
  std::int64_t components = 0;          ///< connected components (by shared edges)
  double volume = 0.0;                  ///< enclosed volume after any winding fix [length^3]
  bool winding_flipped = false;         ///< the signed volume was negative and all triangles were flipped
  bool assumed_open = false;            ///< accepted with holes (MeshLoadOptions::allow_open): inside
                                        ///< tests must use the generalised winding number
  bool closed_manifold() const { return boundary_edges == 0 && non_manifold_edges == 0; }
};
static_assert(std::is_trivially_copyable_v<MeshReport>);

}  // namespace uh::collette
