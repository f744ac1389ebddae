#include "uh/collette/distance_query.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

#include "query_kernels.hpp"

namespace uh::collette {
namespace {

// min-heap on the lower bound
struct HeapGreater {
  bool operator()(const DistanceQuery::HeapEntry& l, const DistanceQuery::HeapEntry& r) const { return l.bound > r.bound; }
};
constexpr HeapGreater heap_greater{};

}  // namespace

DistanceQuery::DistanceQuery(const DistanceQueryOptions& options) : options_(options) {
  heap_.reserve(static_cast<std::size_t>(std::max(64, options_.heap_reserve)));
}

const DistanceResult& DistanceQuery::run(const SphereTree& a, const SphereTree& b, const Pose& b_in_a) {
  assert(!a.empty() && !b.empty() && "uh::collette::DistanceQuery::run(): empty tree");
  result_ = DistanceResult{};
  heap_.clear();
  const detail::FloatTransform xf = detail::FloatTransform::from(b_in_a);
  const SphereTreeNode* const na = a.nodes().data();
  const SphereTreeNode* const nb = b.nodes().data();
  QueryStats stats;
  float best = std::numeric_limits<float>::infinity();
  std::int32_t best_a = -1, best_b = -1;
  float best_bx = 0.f, best_by = 0.f, best_bz = 0.f;

  // tests node pair (ia, ib), B's centre (x, y, z) in A's frame; returns true on leaf overlap
  auto offer = [&](std::int32_t ia, std::int32_t ib, float x, float y, float z) {
    const SphereTreeNode& A = na[ia];
    const SphereTreeNode& B = nb[ib];
    const float dx = x - A.x, dy = y - A.y, dz = z - A.z;
    const float gap = std::sqrt(dx * dx + dy * dy + dz * dz) - A.radius - B.radius;
    if (A.is_leaf() && B.is_leaf()) {
      ++stats.leaf_pairs_tested;
      if (gap < best) {
        best = gap;
        best_a = ia;
        best_b = ib;
        best_bx = x;
        best_by = y;
        best_bz = z;
      }
      return gap <= 0.f;
    }
    if (gap >= best) return false;
    if (heap_.size() == heap_.capacity()) heap_.reserve(2 * heap_.capacity());
    heap_.push_back({gap, ia, ib, x, y, z});
    std::push_heap(heap_.begin(), heap_.end(), heap_greater);
    return false;
  };

  float x, y, z;
  bool overlap = false;
  const bool warm = options_.warm_start && warm_a_ >= 0 && warm_a_ < a.node_count() && warm_b_ >= 0 &&
                    warm_b_ < b.node_count() && na[warm_a_].is_leaf() && nb[warm_b_].is_leaf();
  if (warm) {
    xf.apply(nb[warm_b_].x, nb[warm_b_].y, nb[warm_b_].z, x, y, z);
    overlap = offer(warm_a_, warm_b_, x, y, z);
  }
  if (!overlap) {
    xf.apply(nb[0].x, nb[0].y, nb[0].z, x, y, z);
    overlap = offer(0, 0, x, y, z);
  }
  while (!overlap && !heap_.empty()) {
    std::pop_heap(heap_.begin(), heap_.end(), heap_greater);
    const HeapEntry e = heap_.back();
    heap_.pop_back();
    if (e.bound >= best) break;  // the smallest bound left cannot improve
    ++stats.node_pairs_visited;
    const SphereTreeNode& A = na[e.a];
    const SphereTreeNode& B = nb[e.b];
    if (!A.is_leaf() && (B.is_leaf() || A.radius >= B.radius)) {
      for (std::int32_t i = A.first; i < A.first + A.count && !overlap; ++i) overlap = offer(i, e.b, e.bx, e.by, e.bz);
    } else {
      for (std::int32_t i = B.first; i < B.first + B.count && !overlap; ++i) {
        xf.apply(nb[i].x, nb[i].y, nb[i].z, x, y, z);
        overlap = offer(e.a, i, x, y, z);
      }
    }
  }
  stats.overlapping_pairs = overlap ? 1 : 0;

  DistanceResult& r = result_;
  r.stats = stats;
  r.overlapping = best <= 0.f;
  r.distance = r.overlapping ? 0.0 : static_cast<double>(best);
  if (best_a >= 0) {
    warm_a_ = best_a;
    warm_b_ = best_b;
    const SphereTreeNode& A = na[best_a];
    const SphereTreeNode& B = nb[best_b];
    r.leaf_a = A.first;
    r.leaf_b = B.first;
    const Vec3 ca{static_cast<double>(A.x), static_cast<double>(A.y), static_cast<double>(A.z)};
    const Vec3 cb{static_cast<double>(best_bx), static_cast<double>(best_by), static_cast<double>(best_bz)};
    const Vec3 u = normalized(cb - ca);
    r.point_a = ca + u * static_cast<double>(A.radius);
    r.point_b = cb - u * static_cast<double>(B.radius);
  }
  return r;
}

}  // namespace uh::collette
