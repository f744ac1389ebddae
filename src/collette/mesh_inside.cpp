#include "uh/collette/mesh_inside.hpp"

#include <cmath>

#include "triangle_bvh.hpp"

namespace uh::collette {

struct MeshInside::Impl {
  detail::TriangleBvh bvh;
  bool open = false;
};

MeshInside::MeshInside(const TriangleMesh& mesh) : impl_(std::make_unique<Impl>()) {
  impl_->bvh = detail::TriangleBvh(mesh.vertices, mesh.triangles);
  impl_->open = mesh.report.assumed_open || !mesh.report.closed_manifold();
}

MeshInside::~MeshInside() = default;
MeshInside::MeshInside(MeshInside&&) noexcept = default;
MeshInside& MeshInside::operator=(MeshInside&&) noexcept = default;

bool MeshInside::contains(const Vec3& p) const {
  if (impl_->open) return winding_number(p) > 0.5;
  // three fixed, non-axis-aligned directions: a ray that grazes an edge or vertex (and so
  // counts a crossing twice or not at all) is outvoted by the other two
  static constexpr Vec3 kDirections[3] = {{0.8017837257372732, 0.2672612419124244, 0.5345224838248488},
                                          {-0.3015113445777636, 0.9045340337332909, 0.3015113445777636},
                                          {0.2357022603955158, -0.4714045207910317, 0.8498365855987975}};
  int votes = 0;
  for (const Vec3& d : kDirections) votes += impl_->bvh.ray_crossings(p, d) % 2;
  return votes >= 2;
}

double MeshInside::winding_number(const Vec3& p) const { return impl_->bvh.winding_number(p); }

double MeshInside::distance(const Vec3& p) const { return std::sqrt(impl_->bvh.closest(p)); }

double MeshInside::signed_distance(const Vec3& p) const {
  const double d = distance(p);
  return contains(p) ? -d : d;
}

Vec3 MeshInside::closest_point(const Vec3& p) const {
  Vec3 q{};
  impl_->bvh.closest(p, &q);
  return q;
}

}  // namespace uh::collette
