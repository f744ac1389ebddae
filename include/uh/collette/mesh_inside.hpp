#pragma once
/// \file
/// MeshInside: exact point-to-surface distance and a robust inside test for a triangle mesh.

#include <cstddef>
#include <memory>
#include <span>

#include "uh/collette/triangle_mesh.hpp"

namespace uh::collette {

/// The nearest point of a mesh's surface to a query point (MeshInside::nearest). Plain data.
struct SurfacePoint {
  bool found = false;  ///< a triangle lies within the query's distance
  Vec3 point{};        ///< the nearest point on the surface
  Vec3 face_normal{};  ///< the unit normal of the triangle it lies on (outward for an outward-wound mesh)
  double distance = 0.0;
};

/// Point queries against one mesh, accelerated by a triangle BVH built in the constructor.
///
/// contains() counts signed ray crossings (the winding number along a ray, so interpenetrating
/// closed shells count as inside) along three fixed rays and takes the majority, which is robust
/// when a ray grazes an edge or vertex; for meshes accepted with report.assumed_open it uses the
/// generalised winding number
/// (> 0.5 means inside) for meshes accepted with report.assumed_open. distance() is the exact
/// Euclidean distance to the nearest triangle. Keeps its own copy of the geometry. Const queries
/// are thread-safe and allocation-free, but not bounded-time: keep them off the haptic thread.
class MeshInside {
 public:
  explicit MeshInside(const TriangleMesh& mesh);
  ~MeshInside();
  MeshInside(MeshInside&&) noexcept;
  MeshInside& operator=(MeshInside&&) noexcept;
  MeshInside(const MeshInside&) = delete;
  MeshInside& operator=(const MeshInside&) = delete;

  /// True when p lies strictly inside the closed surface (points on the surface may go either way).
  bool contains(const Vec3& p) const;
  /// Generalised winding number at p: 1 inside and 0 outside a closed outward-oriented mesh,
  /// fractional near holes of an open one. Exact sum over all triangles: O(triangles).
  double winding_number(const Vec3& p) const;
  /// Unsigned distance from p to the nearest point of any triangle [length unit of the mesh].
  double distance(const Vec3& p) const;
  /// Signed distance: negative inside, positive outside.
  double signed_distance(const Vec3& p) const;
  /// Nearest point on the surface to p.
  Vec3 closest_point(const Vec3& p) const;
  /// The nearest point on the surface to p if one lies within `max_distance`, with its triangle's
  /// normal (the side p is on: dot(p - point, face_normal) >= 0 outside a closed outward mesh,
  /// wherever the nearest point is inside a face or on a convex edge or corner). Allocation-free;
  /// the search visits only the BVH nodes within `max_distance`.
  SurfacePoint nearest(const Vec3& p, double max_distance) const;
  /// The faces p lies squarely above: within `max_distance` on the outer side of a triangle's plane,
  /// its foot on that plane inside the triangle (so the distance to the face is the distance to its
  /// plane, exact and linear in p), and its normal turned more than `min_turn` [rad] from
  /// `turned_from` (unit; a zero vector: any face). The nearest out.size() of them, nearest first,
  /// into `out`; returns how many. Where nearest() gives one face, this gives the other faces of a
  /// concave crease or corner; the BVH's normal cones skip the flat and gently curved parts near p
  /// whole. Allocation-free.
  std::size_t faces_below(const Vec3& p, double max_distance, std::span<SurfacePoint> out,
                          const Vec3& turned_from = {}, double min_turn = 0.0) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace uh::collette
