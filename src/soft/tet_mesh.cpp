#include "uh/soft/tet_mesh.hpp"

#include <Eigen/Geometry>

namespace uh::soft {

double tet_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                  const Eigen::Vector3d& d) {
  return (b - a).cross(c - a).dot(d - a) / 6.0;
}

double mesh_volume(const TetMesh& mesh, const std::vector<Eigen::Vector3d>& positions) {
  double volume = 0.0;
  for (const auto& t : mesh.tets) {
    volume += tet_volume(positions[static_cast<std::size_t>(t[0])], positions[static_cast<std::size_t>(t[1])],
                         positions[static_cast<std::size_t>(t[2])], positions[static_cast<std::size_t>(t[3])]);
  }
  return volume;
}

}  // namespace uh::soft
