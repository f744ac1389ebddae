#include "triangle_bvh.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace uh::collette::detail {
namespace {

constexpr int kLeafSize = 4;

double component(const Vec3& v, int axis) { return axis == 0 ? v.x : (axis == 1 ? v.y : v.z); }

}  // namespace

Vec3 closest_point_on_triangle(const Vec3& p, const Triangle& t) {
  const Vec3 ab = t.b - t.a;
  const Vec3 ac = t.c - t.a;
  const Vec3 ap = p - t.a;
  const double d1 = dot(ab, ap);
  const double d2 = dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0) return t.a;
  const Vec3 bp = p - t.b;
  const double d3 = dot(ab, bp);
  const double d4 = dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) return t.b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return t.a + ab * (d1 / (d1 - d3));
  const Vec3 cp = p - t.c;
  const double d5 = dot(ab, cp);
  const double d6 = dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) return t.c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return t.a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    return t.b + (t.c - t.b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  }
  const double denom = va + vb + vc;
  if (!(denom > 0.0)) return t.a;  // degenerate triangle: fall back to a vertex
  return t.a + ab * (vb / denom) + ac * (vc / denom);
}

double triangle_winding(const Vec3& p, const Triangle& t) {
  const Vec3 a = t.a - p;
  const Vec3 b = t.b - p;
  const Vec3 c = t.c - p;
  const double la = norm(a);
  const double lb = norm(b);
  const double lc = norm(c);
  const double num = dot(a, cross(b, c));
  const double den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
  return std::atan2(num, den) / (2.0 * kPi);
}

TriangleBvh::TriangleBvh(const std::vector<Vec3>& vertices,
                         const std::vector<std::array<std::int32_t, 3>>& triangles) {
  tris_.reserve(triangles.size());
  for (const auto& t : triangles) {
    tris_.push_back({vertices[static_cast<std::size_t>(t[0])], vertices[static_cast<std::size_t>(t[1])],
                     vertices[static_cast<std::size_t>(t[2])]});
  }
  if (tris_.empty()) return;
  std::vector<Vec3> centroids(tris_.size());
  for (std::size_t i = 0; i < tris_.size(); ++i) centroids[i] = (tris_[i].a + tris_[i].b + tris_[i].c) / 3.0;
  nodes_.reserve(2 * tris_.size() / kLeafSize + 2);
  nodes_.push_back({});
  // the build permutes triangle ids only; the triangles are put in leaf order once at the end
  std::vector<std::int32_t> order(tris_.size());
  std::iota(order.begin(), order.end(), 0);
  build(0, 0, static_cast<std::int32_t>(tris_.size()), order, centroids);
  std::vector<Triangle> in_leaf_order(tris_.size());
  for (std::size_t i = 0; i < order.size(); ++i) in_leaf_order[i] = tris_[static_cast<std::size_t>(order[i])];
  tris_.swap(in_leaf_order);
  cones_.resize(nodes_.size());
  fit_cone(0);
}

// Bottom-up: a leaf's cone about the mean of its unit normals, an inner node's about the mean of
// its children's axes, wide enough for both children's cones (not the tightest, always enclosing).
NormalCone TriangleBvh::fit_cone(std::int32_t node) {
  const BvhNode& n = nodes_[static_cast<std::size_t>(node)];
  NormalCone cone;
  const auto angle = [](const Vec3& a, const Vec3& b) { return std::acos(std::clamp(dot(a, b), -1.0, 1.0)); };
  if (n.count > 0) {
    Vec3 sum{};
    for (std::int32_t i = n.first; i < n.first + n.count; ++i) {
      const Triangle& t = tris_[static_cast<std::size_t>(i)];
      const Vec3 normal = cross(t.b - t.a, t.c - t.a);
      if (norm(normal) > 0.0) sum += normalized(normal);
    }
    if (norm(sum) > 1e-9) {
      cone.axis = normalized(sum);
      cone.half_angle = 0.0;
      for (std::int32_t i = n.first; i < n.first + n.count; ++i) {
        const Triangle& t = tris_[static_cast<std::size_t>(i)];
        const Vec3 normal = cross(t.b - t.a, t.c - t.a);
        // a degenerate triangle has no normal to bound: the cone opens fully
        cone.half_angle = norm(normal) > 0.0 ? std::max(cone.half_angle, angle(normalized(normal), cone.axis)) : kPi;
      }
    }
  } else {
    const NormalCone l = fit_cone(n.first), r = fit_cone(n.first + 1);
    const Vec3 sum = l.axis + r.axis;
    if (l.half_angle < kPi && r.half_angle < kPi && norm(sum) > 1e-9) {
      cone.axis = normalized(sum);
      cone.half_angle = std::min(kPi, std::max(angle(l.axis, cone.axis) + l.half_angle, angle(r.axis, cone.axis) + r.half_angle));
    }
  }
  cone.cos_half = std::cos(cone.half_angle);
  cone.sin_half = std::sin(cone.half_angle);
  cones_[static_cast<std::size_t>(node)] = cone;
  return cone;
}

void TriangleBvh::build(std::int32_t node, std::int32_t first, std::int32_t count,
                        std::vector<std::int32_t>& order, const std::vector<Vec3>& centroids) {
  Vec3 lo{1e300, 1e300, 1e300};
  Vec3 hi{-1e300, -1e300, -1e300};
  Vec3 clo = lo;
  Vec3 chi = hi;
  for (std::int32_t i = first; i < first + count; ++i) {
    const auto id = static_cast<std::size_t>(order[static_cast<std::size_t>(i)]);
    const Triangle& t = tris_[id];
    for (const Vec3& v : {t.a, t.b, t.c}) {
      lo = {std::min(lo.x, v.x), std::min(lo.y, v.y), std::min(lo.z, v.z)};
      hi = {std::max(hi.x, v.x), std::max(hi.y, v.y), std::max(hi.z, v.z)};
    }
    const Vec3& c = centroids[id];
    clo = {std::min(clo.x, c.x), std::min(clo.y, c.y), std::min(clo.z, c.z)};
    chi = {std::max(chi.x, c.x), std::max(chi.y, c.y), std::max(chi.z, c.z)};
  }
  nodes_[static_cast<std::size_t>(node)].lo = lo;
  nodes_[static_cast<std::size_t>(node)].hi = hi;
  if (count <= kLeafSize) {
    nodes_[static_cast<std::size_t>(node)].first = first;
    nodes_[static_cast<std::size_t>(node)].count = count;
    return;
  }
  const Vec3 ext = chi - clo;
  const int axis = (ext.x >= ext.y && ext.x >= ext.z) ? 0 : (ext.y >= ext.z ? 1 : 2);
  // median split on the longest centroid axis: balanced depth, deterministic (ties by id)
  const std::int32_t half = count / 2;
  const auto begin = order.begin() + first;
  std::nth_element(begin, begin + half, begin + count, [&](std::int32_t a, std::int32_t b) {
    const double ca = component(centroids[static_cast<std::size_t>(a)], axis);
    const double cb = component(centroids[static_cast<std::size_t>(b)], axis);
    return ca < cb || (ca == cb && a < b);
  });
  const auto left = static_cast<std::int32_t>(nodes_.size());
  nodes_.push_back({});
  nodes_.push_back({});
  nodes_[static_cast<std::size_t>(node)].first = left;
  nodes_[static_cast<std::size_t>(node)].count = 0;
  build(left, first, half, order, centroids);
  build(left + 1, first + half, count - half, order, centroids);
}

double TriangleBvh::closest(const Vec3& p, Vec3* nearest, double max_d2, std::int32_t* triangle) const {
  double best = max_d2;
  Vec3 best_point{};
  std::int32_t best_triangle = -1;
  if (tris_.empty()) return best;
  std::int32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const BvhNode& n = nodes_[static_cast<std::size_t>(stack[--top])];
    if (box_distance2(p, n.lo, n.hi) >= best) continue;
    if (n.count > 0) {
      for (std::int32_t i = n.first; i < n.first + n.count; ++i) {
        const Vec3 q = closest_point_on_triangle(p, tris_[static_cast<std::size_t>(i)]);
        const double d2 = squared_norm(q - p);
        if (d2 < best) {
          best = d2;
          best_point = q;
          best_triangle = i;
        }
      }
      continue;
    }
    // visit the nearer child first so that the far one is usually pruned
    const BvhNode& l = nodes_[static_cast<std::size_t>(n.first)];
    const BvhNode& r = nodes_[static_cast<std::size_t>(n.first + 1)];
    const double dl = box_distance2(p, l.lo, l.hi);
    const double dr = box_distance2(p, r.lo, r.hi);
    if (dl <= dr) {
      if (dr < best) stack[top++] = n.first + 1;
      if (dl < best) stack[top++] = n.first;
    } else {
      if (dl < best) stack[top++] = n.first;
      if (dr < best) stack[top++] = n.first + 1;
    }
  }
  if (best_triangle < 0) return best;
  if (nearest != nullptr) *nearest = best_point;
  if (triangle != nullptr) *triangle = best_triangle;
  return best;
}

template <typename Visit>
void TriangleBvh::ray_visit(const Vec3& o, const Vec3& d, double t_max, Visit&& visit) const {
  if (tris_.empty()) return;
  const Vec3 inv{1.0 / d.x, 1.0 / d.y, 1.0 / d.z};
  std::int32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const BvhNode& n = nodes_[static_cast<std::size_t>(stack[--top])];
    // slab test; infinities from zero direction components behave correctly except 0 * inf,
    // which the max/min with the current interval tolerates because NaN comparisons are false
    double t0 = 0.0;
    double t1 = t_max;
    for (int axis = 0; axis < 3; ++axis) {
      const double oa = component(o, axis);
      const double ia = component(inv, axis);
      double ta = (component(n.lo, axis) - oa) * ia;
      double tb = (component(n.hi, axis) - oa) * ia;
      if (std::isnan(ta) || std::isnan(tb)) continue;
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
    }
    if (t0 > t1) continue;
    if (n.count > 0) {
      for (std::int32_t i = n.first; i < n.first + n.count; ++i) {
        const Triangle& t = tris_[static_cast<std::size_t>(i)];
        // Moller-Trumbore; hits exactly on an edge count for both triangles, which the callers
        // detect (coincident parameters) or outvote (three rays)
        const Vec3 e1 = t.b - t.a;
        const Vec3 e2 = t.c - t.a;
        const Vec3 pv = cross(d, e2);
        const double det = dot(e1, pv);
        if (det == 0.0) continue;
        const double inv_det = 1.0 / det;
        const Vec3 tv = o - t.a;
        const double u = dot(tv, pv) * inv_det;
        if (u < 0.0 || u > 1.0) continue;
        const Vec3 qv = cross(tv, e1);
        const double v = dot(d, qv) * inv_det;
        if (v < 0.0 || u + v > 1.0) continue;
        const double tt = dot(e2, qv) * inv_det;
        // det = -dot(d, normal): negative when the ray leaves through the triangle
        if (tt > 0.0 && tt < t_max) visit(tt, det < 0.0 ? 1 : -1);
      }
      continue;
    }
    stack[top++] = n.first;
    stack[top++] = n.first + 1;
  }
}

void TriangleBvh::ray_hits(const Vec3& o, const Vec3& d, double t_max,
                           std::vector<std::pair<double, int>>& hits) const {
  ray_visit(o, d, t_max, [&](double t, int w) { hits.emplace_back(t, w); });
}

int TriangleBvh::ray_winding(const Vec3& o, const Vec3& d) const {
  int w = 0;
  ray_visit(o, d, 1e300, [&](double, int s) { w += s; });
  return w;
}

bool TriangleBvh::inside_vote(const Vec3& p) const {
  // unnormalised, with no simple ratios between components, so that rays from points on
  // rational grids do not run exactly through the edges and vertices of axis-aligned meshes
  static constexpr Vec3 kDirections[3] = {{0.9173251, 0.3281647, 0.2257319},
                                          {-0.2811437, 0.9137213, 0.2935071},
                                          {0.1931559, -0.3512873, 0.9162341}};
  int votes = 0;
  for (const Vec3& d : kDirections) votes += ray_winding(p, d) > 0 ? 1 : 0;
  return votes >= 2;
}

double TriangleBvh::winding_number(const Vec3& p) const {
  double w = 0.0;
  for (const Triangle& t : tris_) w += triangle_winding(p, t);
  return w;
}

}  // namespace uh::collette::detail
