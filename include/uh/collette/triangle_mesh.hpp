#pragma once
/// \file
/// TriangleMesh: an indexed triangle mesh as Collette imports it, plus volume and bounds.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "uh/collette/mesh_report.hpp"
#include "uh/core/math.hpp"

namespace uh::collette {

/// Axis-aligned box [min, max] in the mesh frame [length unit of the mesh].
/// An empty box has min > max on every axis.
struct Aabb {
  Vec3 min{1.0, 1.0, 1.0};
  Vec3 max{-1.0, -1.0, -1.0};
};

/// An indexed triangle mesh in its own frame and units.
///
/// Triangles are counter-clockwise seen from outside (outward normals by the right-hand rule)
/// once load_mesh() or validate_mesh() accepted the mesh. Plain value type: immutable after
/// loading by convention, safe to share read-only between threads. Not used on real-time paths.
struct TriangleMesh {
  std::vector<Vec3> vertices;                            ///< positions [length unit of the file]
  std::vector<std::array<std::int32_t, 3>> triangles;    ///< vertex indices, CCW from outside
  std::string source_name;                               ///< file name (or a made-up name) used in messages
  MeshReport report{};                                   ///< what validation found and what it assumed or fixed
};

/// Signed volume enclosed by the mesh (divergence theorem) [length^3]. Positive for a closed mesh
/// with outward normals, negative when the winding is inverted, meaningless for an open mesh.
/// Any thread; allocation-free.
double mesh_volume(const TriangleMesh& mesh);

/// Bounding box of the vertices; an empty Aabb (min > max) for a mesh without vertices.
Aabb mesh_bounds(const TriangleMesh& mesh);

}  // namespace uh::collette
