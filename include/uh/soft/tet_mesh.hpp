#pragma once

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <vector>

namespace uh::soft {

/// A volume mesh of linear tetrahedra: rest node positions and four node indices per element.
/// Every tetrahedron is positively oriented: (b - a) x (c - a) . (d - a) > 0 for its nodes a, b, c, d.
struct TetMesh {
  std::vector<Eigen::Vector3d> nodes;              ///< rest positions [m], object frame
  std::vector<std::array<std::int32_t, 4>> tets;  ///< node indices, positively oriented
};

/// Signed volume [m^3] of the tetrahedron a, b, c, d (positive when positively oriented).
double tet_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                  const Eigen::Vector3d& d);

/// Total signed volume [m^3] of `mesh`'s tetrahedra at the node positions `positions` (one per node).
double mesh_volume(const TetMesh& mesh, const std::vector<Eigen::Vector3d>& positions);

}  // namespace uh::soft
