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

SurfacePoint MeshInside::nearest(const Vec3& p, double max_distance) const {
  SurfacePoint out;
  std::int32_t triangle = -1;
  const double d2 = impl_->bvh.closest(p, &out.point, max_distance * max_distance, &triangle);
  if (triangle < 0) return out;
  const detail::Triangle& t = impl_->bvh.triangles()[static_cast<std::size_t>(triangle)];
  const Vec3 n = cross(t.b - t.a, t.c - t.a);
  const double length = norm(n);
  out.found = true;
  out.face_normal = length > 0.0 ? n / length : Vec3{};
  out.distance = std::sqrt(d2);
  return out;
}

}  // namespace uh::collette
