#include "uh/collette/volume_query.hpp"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>

#include "query_kernels.hpp"
#include "uh/core/sphere_overlap.hpp"

namespace uh::collette {
namespace {

// Running totals in double: tens of thousands of float pair terms would lose digits otherwise.
struct Totals {
  double volume = 0.0;
  double nx = 0.0, ny = 0.0, nz = 0.0;
  double cx = 0.0, cy = 0.0, cz = 0.0;
};

}  // namespace

VolumeQuery::VolumeQuery(const VolumeQueryOptions& options) : options_(options) {
  options_.pair_capacity = std::max(0, options_.pair_capacity);
  stack_.reserve(static_cast<std::size_t>(std::max(64, options_.stack_reserve)));
  if (options_.collect_pairs) pairs_.resize(static_cast<std::size_t>(options_.pair_capacity));
}

const VolumeQueryResult& VolumeQuery::run(const SphereTree& a, const SphereTree& b, const Pose& b_in_a) {
  assert(!a.empty() && !b.empty() && "uh::collette::VolumeQuery::run(): empty tree");
  result_ = VolumeQueryResult{};
  const detail::FloatTransform xf = detail::FloatTransform::from(b_in_a);
  const SphereTreeNode* const na = a.nodes().data();
  const SphereTreeNode* const nb = b.nodes().data();
  const bool collect = options_.collect_pairs;
  const std::int32_t capacity = collect ? options_.pair_capacity : 0;
  PairOverlap* const out = pairs_.data();
  std::int32_t stored = 0;
  std::int64_t overlapping = 0;
  std::int64_t leaf_tests = 0;
  std::int64_t visited = 0;
  Totals sum;

  // an overlapping leaf pair (dx, dy, dz = b - a in A's frame, d2 its squared length)
  auto add_pair = [&](const SphereTreeNode& la, const SphereTreeNode& lb, float dx, float dy, float dz, float d2) {
    const float d = std::sqrt(d2);
    const float v = lens_volume(d, la.radius, lb.radius);
    if (!(v > 0.f)) return;
    const float off = lens_centroid_offset(d, la.radius, lb.radius);
    const float inv = d > 0.f ? 1.f / d : 0.f;
    const float nx = dx * inv, ny = dy * inv, nz = dz * inv;
    const float cx = la.x + nx * off, cy = la.y + ny * off, cz = la.z + nz * off;
    const double vd = static_cast<double>(v);
    sum.volume += vd;
    sum.nx += vd * static_cast<double>(nx);
    sum.ny += vd * static_cast<double>(ny);
    sum.nz += vd * static_cast<double>(nz);
    sum.cx += vd * static_cast<double>(cx);
    sum.cy += vd * static_cast<double>(cy);
    sum.cz += vd * static_cast<double>(cz);
    ++overlapping;
    if (stored < capacity) {
      PairOverlap& p = out[stored++];
      p.leaf_a = la.first;
      p.leaf_b = lb.first;
      p.volume = v;
      p.normal[0] = nx;
      p.normal[1] = ny;
      p.normal[2] = nz;
      p.centroid[0] = cx;
      p.centroid[1] = cy;
      p.centroid[2] = cz;
    }
  };

  float rbx, rby, rbz;
  xf.apply(nb[0].x, nb[0].y, nb[0].z, rbx, rby, rbz);
  {
    const float dx = rbx - na[0].x, dy = rby - na[0].y, dz = rbz - na[0].z;
    const float d2 = dx * dx + dy * dy + dz * dz;
    const float rs = na[0].radius + nb[0].radius;
    if (d2 < rs * rs) {
      if (na[0].is_leaf() && nb[0].is_leaf()) {
        ++leaf_tests;
        add_pair(na[0], nb[0], dx, dy, dz, d2);
      } else {
        stack_.push_back({0, 0, rbx, rby, rbz});
      }
    } else if (na[0].is_leaf() && nb[0].is_leaf()) {
      ++leaf_tests;
    }
  }

  while (!stack_.empty()) {
    const StackEntry e = stack_.back();
    stack_.pop_back();
    ++visited;
    const SphereTreeNode& A = na[e.a];
    const SphereTreeNode& B = nb[e.b];
    // grow (rarely, outside steady state) before a batch of up to kMaxSphereTreeArity pushes
    if (stack_.capacity() - stack_.size() < static_cast<std::size_t>(kMaxSphereTreeArity))
      stack_.reserve(2 * stack_.capacity());
    if (!A.is_leaf() && (B.is_leaf() || A.radius >= B.radius)) {
      // split A: its children against B (whose centre is already in A's frame)
      const bool b_leaf = B.is_leaf();
      const SphereTreeNode* c = na + A.first;
      for (std::int32_t i = 0; i < A.count; ++i) {
        const float dx = e.bx - c[i].x, dy = e.by - c[i].y, dz = e.bz - c[i].z;
        const float d2 = dx * dx + dy * dy + dz * dz;
        const float rs = c[i].radius + B.radius;
        const bool leaf_pair = b_leaf && c[i].is_leaf();
        leaf_tests += leaf_pair ? 1 : 0;
        if (d2 >= rs * rs) continue;
        if (leaf_pair)
          add_pair(c[i], B, dx, dy, dz, d2);
        else
          stack_.push_back({A.first + i, e.b, e.bx, e.by, e.bz});
      }
    } else {
      // split B: transform each child centre once and test it against A
      const bool a_leaf = A.is_leaf();
      const SphereTreeNode* c = nb + B.first;
      for (std::int32_t i = 0; i < B.count; ++i) {
        float x, y, z;
        xf.apply(c[i].x, c[i].y, c[i].z, x, y, z);
        const float dx = x - A.x, dy = y - A.y, dz = z - A.z;
        const float d2 = dx * dx + dy * dy + dz * dz;
        const float rs = A.radius + c[i].radius;
        const bool leaf_pair = a_leaf && c[i].is_leaf();
        leaf_tests += leaf_pair ? 1 : 0;
        if (d2 >= rs * rs) continue;
        if (leaf_pair) {
          SphereTreeNode moved = c[i];
          moved.x = x;
          moved.y = y;
          moved.z = z;
          add_pair(A, moved, dx, dy, dz, d2);
        } else {
          stack_.push_back({e.a, B.first + i, x, y, z});
        }
      }
    }
  }

  result_.total_volume = sum.volume;
  result_.weighted_normal_sum = {sum.nx, sum.ny, sum.nz};
  result_.restoring_direction = normalized(result_.weighted_normal_sum);
  if (sum.volume > 0.0) result_.volume_centroid = Vec3{sum.cx, sum.cy, sum.cz} / sum.volume;
  result_.pair_count = stored;
  result_.truncated = overlapping > stored && collect;
  result_.stats.node_pairs_visited = visited;
  result_.stats.leaf_pairs_tested = leaf_tests;
  result_.stats.overlapping_pairs = overlapping;
  return result_;
}

void VolumeQuery::run(const SphereTree& a, const SphereTree& b, const Pose& world_from_a, const Pose& world_from_b,
                      ContactFrame& out) {
  const auto start = std::chrono::steady_clock::now();
  const Pose b_in_a = inverse(world_from_a) * world_from_b;
  const VolumeQueryResult& r = run(a, b, b_in_a);
  out.world_from_a = world_from_a;
  out.world_from_b = world_from_b;
  out.total_volume = r.total_volume;
  out.restoring_direction_world = transform_vector(world_from_a, r.restoring_direction);
  out.volume_centroid_world = r.total_volume > 0.0 ? transform_point(world_from_a, r.volume_centroid) : Vec3{};
  out.distance = 0.0;
  const std::int32_t n = std::min<std::int32_t>(r.pair_count, ContactFrame::kMaxPairs);
  const Mat3 m = rotation_matrix(normalized(world_from_a.rotation));
  const auto leaves_a = a.leaves();
  const auto leaves_b = b.leaves();
  for (std::int32_t i = 0; i < n; ++i) {
    const PairOverlap& p = pairs_[static_cast<std::size_t>(i)];
    SpherePairContact& c = out.pairs[static_cast<std::size_t>(i)];
    c.volume = p.volume;
    for (int k = 0; k < 3; ++k) {
      c.normal_world[k] = static_cast<float>(m.m[k][0] * static_cast<double>(p.normal[0]) +
                                             m.m[k][1] * static_cast<double>(p.normal[1]) +
                                             m.m[k][2] * static_cast<double>(p.normal[2]));
    }
    const Vec3 cw = transform_point(world_from_a, Vec3{static_cast<double>(p.centroid[0]), static_cast<double>(p.centroid[1]),
                                                       static_cast<double>(p.centroid[2])});
    c.centroid_world[0] = static_cast<float>(cw.x);
    c.centroid_world[1] = static_cast<float>(cw.y);
    c.centroid_world[2] = static_cast<float>(cw.z);
    c.leaf_a = p.leaf_a;
    c.leaf_b = p.leaf_b;
    c.sphere_a_local = leaves_a[static_cast<std::size_t>(p.leaf_a)];
    c.sphere_b_local = leaves_b[static_cast<std::size_t>(p.leaf_b)];
  }
  out.pair_count = n;
  out.truncated = r.stats.overlapping_pairs > n;
  out.query_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace uh::collette
