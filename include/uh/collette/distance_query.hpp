#pragma once
/// \file
/// DistanceQuery: separation of two sphere packings (proximity query of the Inner Sphere Tree).
///
/// Best-first branch and bound over node pairs on the lower bound |ca - cb| - ra - rb; the answer
/// is the smallest gap between a leaf sphere of A and one of B. Because the spheres lie inside the
/// meshes it is an upper bound on the true mesh separation, too large by at most the packing gaps
/// (the largest distance from a mesh surface to its spheres) of A and B together. 0 when any two
/// leaf spheres overlap or touch. Optionally warm-started with last run's closest leaf pair, whose
/// current gap is an early upper bound (coal-style cached guess).

#include <cstdint>
#include <type_traits>
#include <vector>

#include "uh/collette/query_stats.hpp"
#include "uh/collette/sphere_tree.hpp"
#include "uh/core/math.hpp"

namespace uh::collette {

/// Options for DistanceQuery.
struct DistanceQueryOptions {
  bool warm_start = true;     ///< start from the previous run's closest pair (same trees assumed)
  int heap_reserve = 1024;    ///< initial heap entries (grows once if a query needs more)
};

/// Result of one DistanceQuery::run, A's mesh frame. Trivially copyable.
struct DistanceResult {
  double distance = 0.0;      ///< gap between the closest leaf spheres [length], 0 if overlapping
  bool overlapping = false;   ///< some leaf spheres of A and B overlap or touch
  std::int32_t leaf_a = -1;   ///< index into A.leaves() of the closest (or an overlapping) pair
  std::int32_t leaf_b = -1;   ///< index into B.leaves()
  Vec3 point_a{};             ///< closest point on leaf_a's sphere, A frame [length]
  Vec3 point_b{};             ///< closest point on leaf_b's sphere, A frame [length]
  QueryStats stats{};
};
static_assert(std::is_trivially_copyable_v<DistanceResult>);

/// The reusable distance query. Owns its heap and warm-start pair; no allocation in steady state.
/// Not thread-safe: one object per thread; trees are only read. Use one object per tree pair
/// (the warm start refers to leaf nodes of the last pair of trees; call reset() when switching).
class DistanceQuery {
 public:
  explicit DistanceQuery(const DistanceQueryOptions& options = {});

  /// Separation of B at `b_in_a` (B's mesh frame to A's) from A. Real-time safe in steady state.
  const DistanceResult& run(const SphereTree& a, const SphereTree& b, const Pose& b_in_a);
  /// Forgets the warm-start pair.
  void reset() { warm_a_ = warm_b_ = -1; }
  const DistanceResult& result() const { return result_; }

  /// A waiting node pair with its lower bound on the leaf gap (B's centre in A's frame).
  struct HeapEntry {
    float bound;
    std::int32_t a;
    std::int32_t b;
    float bx, by, bz;
  };

 private:
  DistanceQueryOptions options_;
  std::vector<HeapEntry> heap_;
  std::int32_t warm_a_ = -1;  // leaf node indices of the last closest pair
  std::int32_t warm_b_ = -1;
  DistanceResult result_;
};

}  // namespace uh::collette
