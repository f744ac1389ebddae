#include "uh/collette/time_critical_query.hpp"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>

#include "query_kernels.hpp"
#include "uh/core/sphere_overlap.hpp"

namespace uh::collette {
namespace {

// a function object, not a function pointer, so that the heap operations inline the comparison
struct HeapLess {
  bool operator()(const TimeCriticalQuery::HeapEntry& l, const TimeCriticalQuery::HeapEntry& r) const { return l.key < r.key; }
};
constexpr HeapLess heap_less{};

struct Sums {
  double v = 0.0, nx = 0.0, ny = 0.0, nz = 0.0, cx = 0.0, cy = 0.0, cz = 0.0;
  double gx = 0.0, gy = 0.0, gz = 0.0;  // sum of (expected) intersection disk area * normal

  // adds volume v along the centre line (a -> b) at the lens centroid of the two spheres, and
  // `density` times their intersection disk area (1 for a leaf pair; the node pair's expected
  // share of it for a waiting pair, like its volume)
  void add(const SphereTreeNode& a, float bx, float by, float bz, float rb, float vol, float density) {
    const float dx = bx - a.x, dy = by - a.y, dz = bz - a.z;
    const float d = std::sqrt(dx * dx + dy * dy + dz * dz);
    const float inv = d > 0.f ? 1.f / d : 0.f;
    const SphereOverlap<float> o = sphere_overlap(d, a.radius, rb);
    const float off = o.centroid_offset;
    const double w = static_cast<double>(vol);
    const double g = static_cast<double>(density) * static_cast<double>(o.area);
    v += w;
    nx += w * static_cast<double>(dx * inv);
    ny += w * static_cast<double>(dy * inv);
    nz += w * static_cast<double>(dz * inv);
    gx += g * static_cast<double>(dx * inv);
    gy += g * static_cast<double>(dy * inv);
    gz += g * static_cast<double>(dz * inv);
    cx += w * static_cast<double>(a.x + dx * inv * off);
    cy += w * static_cast<double>(a.y + dy * inv * off);
    cz += w * static_cast<double>(a.z + dz * inv * off);
  }
};

}  // namespace

TimeCriticalQuery::TimeCriticalQuery(const TimeCriticalQueryOptions& options) {
  heap_.reserve(static_cast<std::size_t>(std::max(64, options.heap_reserve)));
}

const TimeCriticalResult& TimeCriticalQuery::run(const SphereTree& a, const SphereTree& b, const Pose& b_in_a,
                                                 const TimeCriticalBudget& budget) {
  assert(!a.empty() && !b.empty() && "uh::collette::TimeCriticalQuery::run(): empty tree");
  result_ = TimeCriticalResult{};
  heap_.clear();
  const auto start = std::chrono::steady_clock::now();
  const detail::FloatTransform xf = detail::FloatTransform::from(b_in_a);
  const SphereTreeNode* const na = a.nodes().data();
  const SphereTreeNode* const nb = b.nodes().data();
  const float* const density_a = a.density().data();
  const float* const density_b = b.density().data();
  Sums exact;
  QueryStats stats;

  // tests node pair (ia, ib) with B's centre (x, y, z) in A's frame: resolves leaf pairs, queues others
  auto offer = [&](std::int32_t ia, std::int32_t ib, float x, float y, float z) {
    const SphereTreeNode& A = na[ia];
    const SphereTreeNode& B = nb[ib];
    const float dx = x - A.x, dy = y - A.y, dz = z - A.z;
    const float d2 = dx * dx + dy * dy + dz * dz;
    const float rs = A.radius + B.radius;
    const bool leaf_pair = A.is_leaf() && B.is_leaf();
    stats.leaf_pairs_tested += leaf_pair ? 1 : 0;
    if (d2 >= rs * rs) return;
    const float lens = lens_volume(std::sqrt(d2), A.radius, B.radius);
    if (leaf_pair) {
      if (lens > 0.f) {
        exact.add(A, x, y, z, B.radius, lens, 1.f);
        ++stats.overlapping_pairs;
      }
      return;
    }
    if (heap_.size() == heap_.capacity()) heap_.reserve(2 * heap_.capacity());
    heap_.push_back({density_a[ia] * density_b[ib] * lens, ia, ib, x, y, z});
    std::push_heap(heap_.begin(), heap_.end(), heap_less);
  };

  float x, y, z;
  xf.apply(nb[0].x, nb[0].y, nb[0].z, x, y, z);
  offer(0, 0, x, y, z);
  std::int64_t expansions = 0;
  while (!heap_.empty()) {
    if (expansions >= budget.max_expansions) break;
    if ((expansions & 15) == 15 && budget.max_seconds < std::numeric_limits<double>::infinity() &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >= budget.max_seconds)
      break;
    std::pop_heap(heap_.begin(), heap_.end(), heap_less);
    const HeapEntry e = heap_.back();
    heap_.pop_back();
    ++expansions;
    const SphereTreeNode& A = na[e.a];
    const SphereTreeNode& B = nb[e.b];
    if (!A.is_leaf() && (B.is_leaf() || A.radius >= B.radius)) {
      for (std::int32_t i = A.first; i < A.first + A.count; ++i) offer(i, e.b, e.bx, e.by, e.bz);
    } else {
      for (std::int32_t i = B.first; i < B.first + B.count; ++i) {
        xf.apply(nb[i].x, nb[i].y, nb[i].z, x, y, z);
        offer(e.a, i, x, y, z);
      }
    }
  }
  stats.node_pairs_visited = expansions;

  // the waiting pairs' share, summed afresh (no drift from incremental add/subtract)
  Sums pending;
  for (const HeapEntry& e : heap_)
    pending.add(na[e.a], e.bx, e.by, e.bz, nb[e.b].radius, e.key, density_a[e.a] * density_b[e.b]);
  TimeCriticalResult& r = result_;
  r.exact_volume = exact.v;
  r.pending_volume = pending.v;
  r.volume_estimate = exact.v + pending.v;
  r.weighted_normal_sum = {exact.nx + pending.nx, exact.ny + pending.ny, exact.nz + pending.nz};
  r.restoring_direction = normalized(r.weighted_normal_sum);
  r.volume_gradient = -Vec3{exact.gx + pending.gx, exact.gy + pending.gy, exact.gz + pending.gz};
  if (r.volume_estimate > 0.0)
    r.volume_centroid = Vec3{exact.cx + pending.cx, exact.cy + pending.cy, exact.cz + pending.cz} / r.volume_estimate;
  r.exact = heap_.empty();
  r.pending_pairs = static_cast<std::int64_t>(heap_.size());
  r.stats = stats;
  return r;
}

}  // namespace uh::collette
