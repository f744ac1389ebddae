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
  return impl_->bvh.inside_vote(p);
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
