#include "uh/soft/surface_mesh.hpp"

#include <algorithm>
#include <map>
#include <utility>

namespace uh::soft {
namespace {

double longest_edge(const SurfaceMesh& mesh) {
  double longest = 0.0;
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const auto a = static_cast<std::size_t>(t[static_cast<std::size_t>(k)]);
      const auto b = static_cast<std::size_t>(t[static_cast<std::size_t>((k + 1) % 3)]);
      longest = std::max(longest, (mesh.vertices[a] - mesh.vertices[b]).norm());
    }
  return longest;
}

// each triangle into four at its edges' midpoints, one midpoint per edge
void split_once(SurfaceMesh& mesh) {
  std::map<std::pair<std::int32_t, std::int32_t>, std::int32_t> midpoints;
  const auto midpoint = [&](std::int32_t a, std::int32_t b) {
    const auto key = std::minmax(a, b);
    const auto [it, added] = midpoints.try_emplace({key.first, key.second}, static_cast<std::int32_t>(mesh.vertices.size()));
    if (added)
      mesh.vertices.push_back(0.5 * (mesh.vertices[static_cast<std::size_t>(a)] + mesh.vertices[static_cast<std::size_t>(b)]));
    return it->second;
  };
  std::vector<std::array<std::int32_t, 3>> split;
  split.reserve(4 * mesh.triangles.size());
  for (const auto& [a, b, c] : mesh.triangles) {
    const std::int32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
    split.push_back({a, ab, ca});
    split.push_back({ab, b, bc});
    split.push_back({ca, bc, c});
    split.push_back({ab, bc, ca});
  }
  mesh.triangles = std::move(split);
}

}  // namespace

SurfaceMesh refine_surface(std::span<const Vec3> vertices, std::span<const std::array<std::int32_t, 3>> triangles) {
  SurfaceMesh mesh;
  mesh.vertices.reserve(vertices.size());
  for (const Vec3& v : vertices) mesh.vertices.emplace_back(v.x, v.y, v.z);
  mesh.triangles.assign(triangles.begin(), triangles.end());
  if (mesh.vertices.empty()) return mesh;
  Eigen::Vector3d lo = mesh.vertices.front(), hi = lo;
  for (const auto& v : mesh.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  const double target = (hi - lo).maxCoeff() / kSurfaceEdgesPerSide;
  while (longest_edge(mesh) > target && 4 * mesh.triangles.size() <= kMaxSurfaceTriangles) split_once(mesh);
  return mesh;
}

}  // namespace uh::soft
