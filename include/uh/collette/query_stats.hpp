#pragma once
/// \file
/// Work counters of one sphere-tree query (volume, time-critical or distance), for benchmarks and
/// for a non-real-time thread to report.

#include <cstdint>
#include <type_traits>

namespace uh::collette {

/// What one query did. Trivially copyable.
struct QueryStats {
  std::int64_t node_pairs_visited = 0;  ///< node pairs taken from the stack or queue and expanded or resolved
  std::int64_t leaf_pairs_tested = 0;   ///< leaf-leaf sphere pairs tested for overlap (or distance)
  std::int64_t overlapping_pairs = 0;   ///< leaf pairs found overlapping (all of them, also beyond a pair capacity)
};
static_assert(std::is_trivially_copyable_v<QueryStats>);

}  // namespace uh::collette
