#include "uh/collette/triangle_mesh.hpp"

#include <algorithm>

namespace uh::collette {

double mesh_volume(const TriangleMesh& mesh) {
  // sum of signed tetrahedra against the bbox centre: same result as against the origin, but
  // with less cancellation for meshes far from it
  const Aabb box = mesh_bounds(mesh);
  const Vec3 o = (box.min + box.max) * 0.5;
  double six_v = 0.0;
  for (const auto& t : mesh.triangles) {
    const Vec3 a = mesh.vertices[static_cast<std::size_t>(t[0])] - o;
    const Vec3 b = mesh.vertices[static_cast<std::size_t>(t[1])] - o;
    const Vec3 c = mesh.vertices[static_cast<std::size_t>(t[2])] - o;
    six_v += dot(a, cross(b, c));
  }
  return six_v / 6.0;
}

Aabb mesh_bounds(const TriangleMesh& mesh) {
  if (mesh.vertices.empty()) return {};
  Aabb box{mesh.vertices.front(), mesh.vertices.front()};
  for (const Vec3& v : mesh.vertices) {
    box.min = {std::min(box.min.x, v.x), std::min(box.min.y, v.y), std::min(box.min.z, v.z)};
    box.max = {std::max(box.max.x, v.x), std::max(box.max.y, v.y), std::max(box.max.z, v.z)};
  }
  return box;
}

}  // namespace uh::collette
