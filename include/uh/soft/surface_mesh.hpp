#pragma once
/// \file
/// A soft object's drawn surface: its mesh, its edges split until they are short enough to show
/// a dent (docs/deformables.md, "Seeing it"). The same refinement serves the simulation, which
/// embeds these vertices in the lattice, and whoever draws them (`uh serve`'s `get_mesh`), so the
/// deformed vertices a session hands out are in this mesh's order.

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "uh/core/math.hpp"

namespace uh::soft {

/// A triangle mesh [m, object frame]: vertices and counter-clockwise triangles (indices).
struct SurfaceMesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::array<std::int32_t, 3>> triangles;
};

/// The refined surface never has more triangles than this (a closed mesh: about half as many
/// vertices), which bounds what a session copies and `uh serve` sends each frame.
inline constexpr std::size_t kMaxSurfaceTriangles = 16384;
/// Edges are split until none is longer than the mesh's longest side over this.
inline constexpr double kSurfaceEdgesPerSide = 16.0;

/// `vertices` (already scaled to metres) and `triangles`, every triangle split into four at its
/// edges' midpoints (shared edges share their midpoint, so a closed mesh stays closed), as many
/// times as it takes for the longest edge to be at most the longest side of the bounds over
/// kSurfaceEdgesPerSide, and no more than kMaxSurfaceTriangles allow. The input's vertices keep
/// their indices; new ones follow. Setup only.
SurfaceMesh refine_surface(std::span<const Vec3> vertices, std::span<const std::array<std::int32_t, 3>> triangles);

}  // namespace uh::soft
