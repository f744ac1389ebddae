#pragma once
/// \file
/// VolumeQuery: the exact intersection volume of two sphere packings, with the restoring
/// direction and the volume centroid (the Inner Sphere Tree penetration-volume query).
///
/// Simultaneous traversal of two SphereTrees A and B that descends only into overlapping node
/// pairs (both inner nodes of a pair are split: each child of B, moved into A's frame once, is
/// tested against all children of A in one SIMD batch, on SphereTree::blocks()); at every
/// overlapping leaf pair it adds the exact lens volume (uh::sphere_overlap), the unit
/// normal along the centre line from A's sphere to B's (pushes B out of A) and the lens centroid.
/// Since the leaves of one object never overlap, the total is exactly the intersection volume of
/// the two packings.
///
/// Usage, one query object per thread, reused every frame:
/// \code
///   uh::collette::VolumeQuery query;                      // reserves its scratch
///   const auto& r = query.run(tree_a, tree_b, b_in_a);    // no allocation in steady state
///   apply(r.total_volume, r.restoring_direction, r.volume_centroid, query.pairs());
/// \endcode

#include <cstdint>
#include <memory>
#include <span>
#include <type_traits>
#include <vector>

#include "uh/collette/query_stats.hpp"
#include "uh/collette/sphere_tree.hpp"
#include "uh/core/contact.hpp"
#include "uh/core/math.hpp"

namespace uh::collette {

namespace detail {
struct LeafBatch;
struct MovedBlocks;
struct QueryWorker;
}  // namespace detail

/// One overlapping leaf pair as the query stores it, in A's mesh frame. 40 bytes.
struct PairOverlap {
  std::int32_t leaf_a = -1;  ///< index into A.leaves()
  std::int32_t leaf_b = -1;  ///< index into B.leaves()
  float volume = 0.f;        ///< lens volume [length^3], > 0 (0 for a near pair of the contact margin)
  float area = 0.f;          ///< pi a^2, area of the intersection disk [length^2] = -d(volume)/d(distance)
  float normal[3] = {};      ///< unit, A frame, from a's centre to b's centre (zero if the centres coincide)
  float centroid[3] = {};    ///< lens centroid, A frame [length]
};
static_assert(std::is_trivially_copyable_v<PairOverlap>);

/// Options for VolumeQuery (Box2D-style aggregate: `VolumeQuery q({.collect_pairs = false});`).
struct VolumeQueryOptions {
  bool collect_pairs = true;      ///< store each overlapping pair in pairs(); totals are always computed
  /// Most pairs stored (the query's own buffer, 40 bytes a pair, one per query object); further
  /// pairs set `truncated`. Frames are sized by what each run stored, not by this.
  int pair_capacity = 32768;
  /// Also store leaf pairs that are apart by less than this [length], with volume 0, normal along
  /// their centre line and centroid on A's sphere towards B. For multi-rate force rendering: a
  /// holder of the pair set re-evaluates them every haptic tick and sees them start to overlap
  /// before the next query, so contacts begin without a step. 0 (default): overlapping pairs only.
  /// Totals never include them.
  float contact_margin = 0.f;
  int stack_reserve = 1024;       ///< initial traversal stack entries (grows once if a query needs more)
  /// Frame-to-frame coherence (a Verlet list): 0 (default) traverses the trees on every run. A
  /// positive skin [length] makes a traversal also keep every leaf pair apart by less than
  /// `contact_margin + coherence_skin` as a candidate; the following runs skip the traversal and
  /// test only those candidates for as long as no point of B has moved (relative to A) by more than
  /// the skin since then: a pair outside the candidates was farther apart than margin + skin, so it
  /// cannot overlap yet. Results are exactly those of a traversal (same pairs, totals equal up to
  /// summation order). Pays when B moves little between runs (a haptic tool at kilohertz rates) and
  /// the skin holds few more pairs than overlap: docs/collette-queries.md, "Coherence".
  float coherence_skin = 0.f;
  int candidate_reserve = 0;      ///< initial candidate entries (0: twice pair_capacity, at least 1024)
  /// Evaluate leaf pairs one at a time with the scalar lens kernel, as before the SIMD kernels:
  /// the reference that tests and benchmarks compare the fast path with. Same results (the same
  /// pairs, bit for bit, and the same totals), slower.
  bool reference_kernel = false;
  /// Run the fast path's node tests and lens kernel eight lanes wide (AVX2) when the CPU has AVX2
  /// (sixteen with use_avx512), checked once at construction (VolumeQuery::kernel_lanes()); false
  /// keeps the baseline kernels
  /// (SSE2, four lanes), which every x86-64 runs. Both give the same results, bit for bit. Builds
  /// for Windows have the baseline kernels only.
  bool use_avx2 = true;
  /// With use_avx2: run them sixteen lanes wide (AVX-512) when the CPU has AVX-512 F, VL, DQ and
  /// BW and is AMD's (VolumeQuery::uses_avx512()): Intel's AVX-512 cores lower their clock for
  /// 512-bit arithmetic, and there the AVX2 kernels measured faster (docs/benchmarks.md); false
  /// stops at AVX2. Same results, bit for bit. Builds for Windows leave it out, as the AVX2 kernels.
  bool use_avx512 = true;
  /// With use_avx2 and use_avx512: take the AVX-512 kernels on any CPU that has them, Intel's too
  /// (tests and benchmarks compare every width).
  bool force_avx512 = false;
  /// Share each traversal with a second thread that the query owns (started at construction,
  /// joined by the destructor; it sleeps between runs): the calling thread runs the first node
  /// pairs, then both take chunks of the remaining frontier, the caller from the front and the
  /// worker from the back, and the caller adds the worker's pairs after its own. Same results as
  /// one thread, bit for bit (pairs in the same order, totals summed in the same order). Pays only
  /// when a second core is free: if the worker is not running when the caller gets to its chunks,
  /// the caller takes them all and the run costs what one thread costs. The fast path only (not
  /// the reference kernel, not runs that keep coherence candidates). The worker keeps up to
  /// pair_capacity pairs (whether or not collect_pairs); when its chunks find more, the caller runs
  /// them again itself. Allocates the worker's buffers (40 bytes a pair of pair_capacity) at
  /// construction; runs stay free of allocation and locks.
  bool worker_thread = false;
  /// With worker_thread: the caller takes no chunk until the worker has claimed one, so that the
  /// worker's part runs in every run (for tests: without it, a worker that a loaded machine does
  /// not schedule in time leaves every chunk to the caller). Costs the worker's wake-up time.
  bool worker_claims_first = false;
};

/// Totals of one VolumeQuery::run, in A's mesh frame. Trivially copyable.
struct VolumeQueryResult {
  double total_volume = 0.0;        ///< sum of the pair lens volumes [length^3], >= 0
  Vec3 restoring_direction{};       ///< unit direction of sum(volume * normal), A frame; zero if none
  Vec3 weighted_normal_sum{};       ///< sum(volume * normal), A frame [length^3]
  Vec3 volume_centroid{};           ///< volume-weighted mean of the lens centroids, A frame [length]; zero if none
  /// dV/d(translation of B), A frame [length^2]: -sum(pi a^2 normal), a = radius of each pair's
  /// intersection circle. The exact gradient of total_volume; -volume_gradient is the direction
  /// that reduces the overlap fastest (measured closer to the true mesh gradient than
  /// restoring_direction: 2-4 deg against 6-7 deg on the bunny) and |volume_gradient| is the
  /// local stiffness of a volume penalty along it.
  Vec3 volume_gradient{};
  /// This run tested the candidates kept by an earlier traversal instead of traversing
  /// (coherence_skin > 0 only); stats.node_pairs_visited is then 0.
  bool reused_candidates = false;
  std::int64_t candidate_pairs = 0; ///< candidates kept (coherence_skin > 0 only), tested this run
  std::int32_t pair_count = 0;      ///< pairs stored in pairs() (<= pair_capacity), near pairs included
  std::int64_t near_pairs = 0;      ///< pairs within contact_margin that do not overlap (stored with volume 0)
  bool truncated = false;           ///< more pairs overlapped than pair_capacity (totals still cover all)
  QueryStats stats{};
};
static_assert(std::is_trivially_copyable_v<VolumeQueryResult>);

/// The reusable volume query. Owns its scratch (traversal stack, pair buffer), reserved at
/// construction; a run allocates only when its stack outgrows every earlier run (so never in
/// steady state). Not thread-safe: one object per thread. The trees are only read.
class VolumeQuery {
 public:
  explicit VolumeQuery(const VolumeQueryOptions& options = {});
  ~VolumeQuery();
  VolumeQuery(VolumeQuery&&) noexcept;
  VolumeQuery& operator=(VolumeQuery&&) noexcept;

  /// Runs the query for B at pose `b_in_a` (maps B's mesh frame to A's mesh frame).
  /// Returns the totals (valid until the next run); pairs() holds the stored pairs.
  /// Real-time safe in steady state: no allocation, lock, exception or logging.
  /// Both trees must be non-empty (validate()d).
  const VolumeQueryResult& run(const SphereTree& a, const SphereTree& b, const Pose& b_in_a);

  /// Runs the query for A and B at their world poses and fills `out` in the world frame:
  /// totals, restoring direction, centroid, the pairs (all the query stored, see pair_capacity;
  /// `truncated` beyond), one section when there are pairs, `distance` = 0, `query_seconds`. Leaves
  /// `sequence`, `time_s` and the object ids (also the section's) for the caller. Pairs are
  /// copied from the query's pair buffer, so construct the query with `collect_pairs` (the default).
  /// Allocates only when `out` has never held as many pairs (the frame grows; it does not shrink).
  void run(const SphereTree& a, const SphereTree& b, const Pose& world_from_a, const Pose& world_from_b,
           ContactFrame& out);
  /// Runs the query and appends its pairs and one section (ids left for the caller) to `out`,
  /// leaving the frame's header alone: a frame of several object pairs is built from these.
  /// Returns the section (valid until the next append). Allocation as in run().
  const ContactSection& append_section(const SphereTree& a, const SphereTree& b, const Pose& world_from_a,
                                       const Pose& world_from_b, ContactFrame& out);

  /// Forgets the coherence candidates: the next run traverses. Call it when a tree changes (runs
  /// with other trees than the last traversal's do this themselves, by address).
  void reset_coherence() { candidate_tree_a_ = candidate_tree_b_ = nullptr; }

  /// The totals of the last run.
  const VolumeQueryResult& result() const { return result_; }
  /// The overlapping pairs stored by the last run (empty unless collect_pairs), A frame.
  std::span<const PairOverlap> pairs() const { return {pairs_.data(), static_cast<std::size_t>(result_.pair_count)}; }
  const VolumeQueryOptions& options() const { return options_; }
  /// Sets options().contact_margin for the next runs (a world whose objects have their own
  /// margins); the kept coherence candidates are forgotten when it changes.
  void set_contact_margin(float margin) {
    if (margin == options_.contact_margin) return;
    options_.contact_margin = margin;
    reset_coherence();
  }
  /// The fast path's kernel width, chosen at construction: 16 (AVX-512: options().use_avx2,
  /// use_avx512 and the CPU has it and is AMD's, or force_avx512), 8 (AVX2: use_avx2 and the CPU
  /// has it) or 4 (the baseline).
  int kernel_lanes() const { return kernel_lanes_; }
  /// True when runs take the AVX2 kernels (eight lanes).
  bool uses_avx2() const { return kernel_lanes_ == 8; }
  /// True when runs take the AVX-512 kernels (sixteen lanes).
  bool uses_avx512() const { return kernel_lanes_ == 16; }
  /// Node-pair chunks that the worker thread ran in the last run (worker_thread only; 0 when the
  /// calling thread ran them all).
  int worker_chunks() const { return worker_chunks_; }

  /// StackEntry::rows of a pair whose rows were not tested when it was pushed.
  static constexpr std::uint32_t kRowsUnknown = ~0u;
  /// One entry of the traversal stack: a node pair known to overlap, as traversal ids
  /// (SphereTree::Blocks), with both node spheres, B's already in A's frame (so each B node is
  /// transformed once per visit).
  struct StackEntry {
    std::int32_t a;
    std::int32_t b;
    float ax, ay, az, ar;
    float bx, by, bz, br;
    /// Fast path: bit j set when child j of B reaches A's node sphere, found when the pair was
    /// pushed; kRowsUnknown when not tested.
    std::uint32_t rows = kRowsUnknown;
    std::uint32_t unused = 0;  ///< pads the entry to three 16-byte pieces (the fast path's stores and loads)
  };

  /// A kept leaf pair: A's leaf index and the slot of B's leaf in the run's moved-B-leaves buffer.
  struct Candidate {
    std::int32_t leaf_a;
    std::int32_t slot_b;
  };

 private:
  void traverse(const SphereTree& a, const SphereTree& b, const Pose& b_in_a, bool keep_candidates);
  void test_candidates(const SphereTree& a, const SphereTree& b, const Pose& b_in_a);
  bool candidates_hold(const SphereTree& a, const SphereTree& b, const Pose& b_in_a) const;

  VolumeQueryOptions options_;
  std::unique_ptr<detail::LeafBatch> batch_;  // leaf pairs waiting for the SIMD lens kernel (10 KB)
  std::unique_ptr<detail::MovedBlocks> moved_;  // B's blocks moved into A's frame this run (fast path)
  std::vector<StackEntry> stack_;
  std::vector<PairOverlap> pairs_;
  VolumeQueryResult result_;
  int kernel_lanes_ = 4;
  int worker_chunks_ = 0;
  std::unique_ptr<detail::QueryWorker> worker_;  // the second thread and its buffers (worker_thread only)
  // coherence: the kept pairs, B's leaves among them (by index) and where they are this run, and
  // the trees and pose of the traversal that kept them
  std::vector<Candidate> candidates_;
  std::vector<std::int32_t> candidate_leaves_b_;
  std::vector<std::int32_t> slot_of_leaf_b_;
  std::vector<Sphere> moved_leaves_b_;
  const SphereTree* candidate_tree_a_ = nullptr;
  const SphereTree* candidate_tree_b_ = nullptr;
  Pose candidate_pose_{};
};

}  // namespace uh::collette
