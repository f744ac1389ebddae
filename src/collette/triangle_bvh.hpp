#pragma once
// Private: a binary BVH over a triangle mesh for exact closest-point and ray-crossing queries.
// Used by MeshInside, the sphere packer and the mesh validation; not part of the public API.

#include <algorithm>
#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "uh/core/math.hpp"

namespace uh::collette::detail {

struct Triangle {
  Vec3 a, b, c;
};

/// Closest point to p on triangle t (Ericson, Real-Time Collision Detection, 5.1.5).
Vec3 closest_point_on_triangle(const Vec3& p, const Triangle& t);

/// Solid angle of triangle t seen from p, divided by 4 pi (Van Oosterom & Strackee).
double triangle_winding(const Vec3& p, const Triangle& t);

/// Squared distance from p to the box [lo, hi] (0 inside).
inline double box_distance2(const Vec3& p, const Vec3& lo, const Vec3& hi) {
  const double dx = std::max({lo.x - p.x, 0.0, p.x - hi.x});
  const double dy = std::max({lo.y - p.y, 0.0, p.y - hi.y});
  const double dz = std::max({lo.z - p.z, 0.0, p.z - hi.z});
  return dx * dx + dy * dy + dz * dz;
}

struct BvhNode {
  Vec3 lo, hi;
  std::int32_t first = 0;  // leaf: first triangle in the permuted order; inner: left child index
  std::int32_t count = 0;  // leaf: triangle count (> 0); inner: 0 (right child = left + 1)
};

/// The normals of a node's triangles all lie within `half_angle` of `axis` (unit) [rad].
struct NormalCone {
  Vec3 axis{};
  double half_angle = kPi;
  double cos_half = -1.0, sin_half = 0.0;  // of half_angle, for the queries' tests
};

class TriangleBvh {
 public:
  TriangleBvh() = default;
  TriangleBvh(const std::vector<Vec3>& vertices, const std::vector<std::array<std::int32_t, 3>>& triangles);

  bool empty() const { return tris_.empty(); }
  /// Squared distance to the nearest triangle, with the nearest point and that triangle's index in
  /// triangles(); `max_d2` prunes the search (nothing nearer: max_d2, and the outputs untouched).
  double closest(const Vec3& p, Vec3* nearest = nullptr, double max_d2 = 1e300,
                 std::int32_t* triangle = nullptr) const;
  /// Calls visit(index) for every triangle whose node's box lies within sqrt(max_d2) of p and whose
  /// nodes' normal cones keep(cone) accepts (a superset of the triangles the caller wants: it
  /// measures them). No allocation.
  template <typename Keep, typename Visit>
  void visit_near(const Vec3& p, double max_d2, Keep&& keep, Visit&& visit) const;
  /// Crossings of the ray o + t d with 0 < t < t_max, appended as (t, w): w = +1 where the ray
  /// leaves through a triangle (along its outward normal), -1 where it enters.
  void ray_hits(const Vec3& o, const Vec3& d, double t_max, std::vector<std::pair<double, int>>& hits) const;
  /// Winding number of a closed, outward-oriented mesh at o, counted along the ray o + t d,
  /// t > 0: the sum of the crossing signs (no allocation). Interpenetrating closed shells give 2
  /// where they overlap, which parity would call outside.
  int ray_winding(const Vec3& o, const Vec3& d) const;
  /// Majority vote of ray_winding() > 0 along three fixed directions: a ray that grazes an edge
  /// or a vertex (counting a crossing twice or not at all) is outvoted by the other two.
  bool inside_vote(const Vec3& p) const;
  /// Exact generalised winding number (sum over all triangles).
  double winding_number(const Vec3& p) const;

  const std::vector<Triangle>& triangles() const { return tris_; }

 private:
  void build(std::int32_t node, std::int32_t first, std::int32_t count, std::vector<std::int32_t>& order,
             const std::vector<Vec3>& centroids);
  template <typename Visit>
  void ray_visit(const Vec3& o, const Vec3& d, double t_max, Visit&& visit) const;

  NormalCone fit_cone(std::int32_t node);

  std::vector<Triangle> tris_;
  std::vector<BvhNode> nodes_;
  std::vector<NormalCone> cones_;  // per node
};

template <typename Keep, typename Visit>
void TriangleBvh::visit_near(const Vec3& p, double max_d2, Keep&& keep, Visit&& visit) const {
  if (tris_.empty()) return;
  std::int32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const auto at = static_cast<std::size_t>(stack[--top]);
    const BvhNode& n = nodes_[at];
    if (box_distance2(p, n.lo, n.hi) > max_d2 || !keep(cones_[at])) continue;
    if (n.count > 0) {
      for (std::int32_t i = n.first; i < n.first + n.count; ++i) visit(i);
    } else {
      stack[top++] = n.first;
      stack[top++] = n.first + 1;
    }
  }
}

}  // namespace uh::collette::detail
