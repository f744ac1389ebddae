#include "uh/collette/mesh_inside.hpp"

#include <algorithm>
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

namespace {

// p's foot on the plane of t, when it lies inside t (barycentric, with a sliver of tolerance so a
// foot on an edge counts for both faces: the caller drops the repeat), and p's height above it.
bool foot_inside(const Vec3& p, const detail::Triangle& t, Vec3& normal, double& height) {
  const Vec3 e0 = t.b - t.a, e1 = t.c - t.a;
  const Vec3 n = cross(e0, e1);
  const double area2 = dot(n, n);
  if (!(area2 > 0.0)) return false;
  const Vec3 ap = p - t.a;
  // barycentric coordinates of the foot, from the signed areas it makes with each edge
  const double v = dot(cross(ap, e1), n) / area2;
  const double w = dot(cross(e0, ap), n) / area2;
  constexpr double kSliver = -1e-9;
  if (v < kSliver || w < kSliver || 1.0 - v - w < kSliver) return false;
  normal = n / std::sqrt(area2);
  height = dot(ap, normal);
  return true;
}

}  // namespace

std::size_t MeshInside::faces_below(const Vec3& p, double max_distance, std::span<SurfacePoint> out,
                                    const Vec3& turned_from, double min_turn) const {
  std::size_t count = 0;
  const auto& triangles = impl_->bvh.triangles();
  const bool any = !(min_turn > 0.0) || !(norm(turned_from) > 0.0);
  const double cos_turn = std::cos(min_turn), sin_turn = std::sin(min_turn);
  // a node whose every normal lies within min_turn of turned_from holds no face wanted: its axis
  // within min_turn - half_angle of it, cos(min_turn - half_angle) expanded so no node needs acos
  const auto keep = [&](const detail::NormalCone& cone) {
    if (any || cone.half_angle >= min_turn) return true;
    return dot(cone.axis, turned_from) < cos_turn * cone.cos_half + sin_turn * cone.sin_half;
  };
  impl_->bvh.visit_near(p, max_distance * max_distance, keep, [&](std::int32_t i) {
    Vec3 normal{};
    double height = 0.0;
    if (!foot_inside(p, triangles[static_cast<std::size_t>(i)], normal, height)) return;
    if (!any && dot(normal, turned_from) >= cos_turn) return;
    if (!(height >= 0.0 && height <= max_distance)) return;
    // insert, nearest first, into the `out.size()` kept so far
    std::size_t at = count < out.size() ? count : out.size();
    while (at > 0 && out[at - 1].distance > height) --at;
    if (at >= out.size()) return;
    for (std::size_t j = std::min(count, out.size() - 1); j > at; --j) out[j] = out[j - 1];
    out[at] = {.found = true, .point = p - height * normal, .face_normal = normal, .distance = height};
    count = std::min(count + 1, out.size());
  });
  return count;
}

}  // namespace uh::collette
