#pragma once
/// \file
/// TimeCriticalQuery: the intersection volume of two sphere packings under a work or time budget.
///
/// Node pairs wait in a max-heap keyed by their expected overlap
/// `density(a) * density(b) * lens_volume(bounding sphere a, bounding sphere b)`, with
/// density = leaf volume below a node / volume of its bounding sphere. The query expands the pair
/// with the largest expected overlap first (splitting the larger sphere, like VolumeQuery); leaf
/// pairs are resolved exactly at once. When the budget ends the estimate is
/// `exact part + sum of the waiting pairs' expected overlaps`; when the heap drains (unbounded
/// budget) the estimate is the exact VolumeQuery result. The direction, the volume gradient and the
/// centroid are estimated the same way (waiting pairs along their centre line, at their
/// bounding-sphere lens centroid).

#include <cstdint>
#include <limits>
#include <type_traits>
#include <vector>

#include "uh/collette/query_stats.hpp"
#include "uh/collette/sphere_tree.hpp"
#include "uh/core/math.hpp"

namespace uh::collette {

/// How much work one TimeCriticalQuery::run may do. Whichever limit is reached first stops it.
struct TimeCriticalBudget {
  std::int64_t max_expansions = std::numeric_limits<std::int64_t>::max();  ///< node pairs taken from the heap
  double max_seconds = std::numeric_limits<double>::infinity();             ///< wall time [s], checked every 16 expansions
};

/// Options for TimeCriticalQuery.
struct TimeCriticalQueryOptions {
  int heap_reserve = 1 << 14;  ///< initial heap entries (grows once if a query needs more)
};

/// Estimate of one TimeCriticalQuery::run, A's mesh frame. Trivially copyable.
struct TimeCriticalResult {
  double volume_estimate = 0.0;   ///< exact_volume + pending_volume [length^3]
  double exact_volume = 0.0;      ///< volume of the leaf pairs resolved exactly [length^3]
  double pending_volume = 0.0;    ///< expected overlap of the pairs still waiting [length^3]
  Vec3 weighted_normal_sum{};     ///< estimate of sum(volume * normal), A frame [length^3]
  Vec3 restoring_direction{};     ///< unit weighted_normal_sum; zero if none
  /// Estimate of d(volume)/d(translation of B), A frame [length^2]: -sum(pi a^2 normal) over the
  /// resolved leaf pairs plus, for each waiting node pair, density(a) density(b) times its bounding
  /// spheres' disk area along their centre line. Equals VolumeQuery's volume_gradient when exact;
  /// its negation is the direction of the gradient force law.
  Vec3 volume_gradient{};
  Vec3 volume_centroid{};         ///< estimate of the volume centroid, A frame [length]; zero if none
  bool exact = false;             ///< the heap drained: the estimate is the exact result
  std::int64_t pending_pairs = 0; ///< node pairs left in the heap
  QueryStats stats{};
};
static_assert(std::is_trivially_copyable_v<TimeCriticalResult>);

/// The reusable time-critical query. Owns a preallocated heap; no allocation in steady state.
/// Not thread-safe: one object per thread; trees are only read.
class TimeCriticalQuery {
 public:
  explicit TimeCriticalQuery(const TimeCriticalQueryOptions& options = {});

  /// Estimates the overlap of B at `b_in_a` (B's mesh frame to A's) with A within `budget`.
  /// Real-time safe in steady state. Both trees must be non-empty.
  const TimeCriticalResult& run(const SphereTree& a, const SphereTree& b, const Pose& b_in_a,
                                const TimeCriticalBudget& budget = {});

  const TimeCriticalResult& result() const { return result_; }

  /// A waiting node pair (B's centre already in A's frame) and its expected overlap.
  struct HeapEntry {
    float key;      ///< expected overlap [length^3]
    std::int32_t a;
    std::int32_t b;
    float bx, by, bz;
  };

 private:
  std::vector<HeapEntry> heap_;
  TimeCriticalResult result_;
};

}  // namespace uh::collette
