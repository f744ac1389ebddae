#include "uh/collette/volume_query.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cassert>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <thread>
#include <type_traits>

#include "lanes_sse2.hpp"
#include "uh/core/address_wait.hpp"
#include "volume_traversal.hpp"

namespace uh::collette {

namespace detail::sse2 {
using V = F4;
template <int W>
using BlockLanes = F4;
#include "volume_fast_path.inl"
}  // namespace detail::sse2

using detail::Traversal;

namespace detail {

// The second thread of a query with worker_thread, and what the two threads share during a run.
//
// A run's frontier (the stack after the caller's first visits, in the order the one-thread
// traversal would take it) is cut into chunks of contiguous entries. One atomic word holds the
// next chunk from the front (the caller's) and the end of the unclaimed chunks (the worker takes
// from there, backwards): each claims with a compare-and-swap, so every chunk runs exactly once
// and the caller's chunks are a prefix. The worker evaluates its chunks into its own stack, batch
// and pair buffer, notes where each chunk's pairs start, and counts finished chunks with a release
// store; the caller waits (spinning) until every chunk the worker claimed is finished, then adds
// those pairs after its own, chunk by chunk in frontier order: the pairs and the order of the sums
// are the one-thread traversal's. Data crosses threads only through these atomics (acquire and
// release): the caller writes the job before it publishes the chunk word and the posted count.
struct QueryWorker {
  static constexpr int kMaxChunks = 16;
  static constexpr std::size_t kFrontier = 40;  // node pairs to share out

  // the job (written by the caller before it posts, read by the worker after it claims a chunk)
  Traversal traversal{};
  std::vector<VolumeQuery::StackEntry> frontier;  // in the order the one-thread traversal takes them
  int chunk_begin[kMaxChunks + 1] = {};           // chunk c: frontier[chunk_begin[c], chunk_begin[c + 1])
  int lanes = 4;                                  // the kernel width (VolumeQuery::kernel_lanes())
  // the worker's scratch and results
  std::vector<VolumeQuery::StackEntry> stack;
  std::unique_ptr<LeafBatch> batch = std::make_unique<LeafBatch>();
  std::unique_ptr<MovedBlocks> moved = std::make_unique<MovedBlocks>();
  std::vector<PairOverlap> pairs;
  int chunk_first_pair[kMaxChunks] = {};  // where chunk c's pairs start in `pairs` (worker's chunks)
  int chunk_pair_count[kMaxChunks] = {};

  std::atomic<std::uint32_t> claim{0};   // low 16 bits: the caller's next chunk; high: end of the unclaimed
  std::atomic<int> finished{0};          // chunks the worker finished this run
  std::atomic<std::uint32_t> posted{0};  // runs posted; the worker wakes when it changes
  std::atomic<bool> stop{false};
  std::thread thread;

  explicit QueryWorker(int pair_capacity)
      : stack(4096), pairs(static_cast<std::size_t>(std::max(pair_capacity, 1))) {
    frontier.reserve(kFrontier + 64);
    thread = std::thread([this] { loop(); });
  }
  ~QueryWorker() {
    stop.store(true, std::memory_order_release);
    posted.fetch_add(1, std::memory_order_release);
    wake_one(posted);
    thread.join();
  }
  QueryWorker(const QueryWorker&) = delete;
  QueryWorker& operator=(const QueryWorker&) = delete;

  // the caller's next chunk, or -1 when none is left
  int claim_front() {
    std::uint32_t cur = claim.load(std::memory_order_acquire);
    for (;;) {
      const std::uint32_t lo = cur & 0xffffu, hi = cur >> 16;
      if (lo >= hi) return -1;
      if (claim.compare_exchange_weak(cur, (hi << 16) | (lo + 1), std::memory_order_acq_rel))
        return static_cast<int>(lo);
    }
  }
  int claim_back() {
    std::uint32_t cur = claim.load(std::memory_order_acquire);
    for (;;) {
      const std::uint32_t lo = cur & 0xffffu, hi = cur >> 16;
      if (lo >= hi) return -1;
      if (claim.compare_exchange_weak(cur, ((hi - 1) << 16) | lo, std::memory_order_acq_rel))
        return static_cast<int>(hi - 1);
    }
  }

  // runs chunk c of the frontier on `t` (whose stack is empty): its entries pushed so that the
  // first is on top, then traversed to the end
  void run_chunk(Traversal& t, int c) const {
    for (int i = chunk_begin[c + 1] - 1; i >= chunk_begin[c]; --i)
      (*t.stack)[t.top++] = frontier[static_cast<std::size_t>(i)];
    run_fast(lanes, t);
  }

  void loop() {
    std::uint32_t seen = 0;
    for (;;) {
      // spin briefly (the next run of a kilohertz loop comes soon), then sleep until posted
      std::uint32_t now = posted.load(std::memory_order_acquire);
      for (int spin = 0; now == seen && spin < 20000; ++spin) {
#if defined(__SSE2__)
        _mm_pause();
#endif
        now = posted.load(std::memory_order_acquire);
      }
      while (now == seen) {
        wait_while_equal(posted, seen);
        now = posted.load(std::memory_order_acquire);
      }
      seen = now;
      if (stop.load(std::memory_order_acquire)) return;
      for (int c = claim_back(); c >= 0; c = claim_back()) {
        chunk_first_pair[c] = traversal.stored;
        run_chunk(traversal, c);
        chunk_pair_count[c] = traversal.stored - chunk_first_pair[c];
        finished.fetch_add(1, std::memory_order_release);
      }
    }
  }
};

}  // namespace detail

VolumeQuery::VolumeQuery(const VolumeQueryOptions& options)
    : options_(options),
      batch_(std::make_unique<detail::LeafBatch>()),
      moved_(std::make_unique<detail::MovedBlocks>()),
      kernel_lanes_(!options.use_avx2 ? 4
                    : options.use_avx512 && detail::avx512::supported() &&
                            (options.force_avx512 || detail::avx512::preferred())
                        ? 16
                    : detail::avx2::supported() ? 8
                                                : 4) {
  if (options_.worker_thread) worker_ = std::make_unique<detail::QueryWorker>(options_.pair_capacity);
  options_.pair_capacity = std::max(0, options_.pair_capacity);
  // the traversal keeps its own top: the vector is storage, sized to its capacity
  stack_.resize(static_cast<std::size_t>(std::max(64, options_.stack_reserve)));
  if (options_.collect_pairs) pairs_.resize(static_cast<std::size_t>(options_.pair_capacity));
  options_.coherence_skin = std::isfinite(options_.coherence_skin) ? std::max(0.f, options_.coherence_skin) : 0.f;
  if (options_.coherence_skin > 0.f) {
    const int reserve = options_.candidate_reserve > 0 ? options_.candidate_reserve : std::max(1024, 2 * options_.pair_capacity);
    candidates_.reserve(static_cast<std::size_t>(reserve));
  }
}

VolumeQuery::~VolumeQuery() = default;
VolumeQuery::VolumeQuery(VolumeQuery&&) noexcept = default;
VolumeQuery& VolumeQuery::operator=(VolumeQuery&&) noexcept = default;

namespace {

// The fast path shared with the worker thread (QueryWorker): returns the chunks the worker ran.
int run_shared(detail::QueryWorker& w, Traversal& t, int lanes, const SphereTree& a, const SphereTree& b,
               const Pose& b_in_a, const VolumeQueryOptions& options) {
  using detail::QueryWorker;
  detail::expand(lanes, t, QueryWorker::kFrontier);
  if (t.top < 2) {
    detail::run_fast(lanes, t);
    return 0;
  }
  // the frontier in the order one thread would take it (top of the stack first), cut into chunks
  // of about equal expected work: the lens volume of a pair's two node spheres
  w.frontier.clear();
  float total = 0.f;
  for (std::size_t i = t.top; i-- > 0;) {
    const VolumeQuery::StackEntry& e = (*t.stack)[i];
    w.frontier.push_back(e);
    const float dx = e.bx - e.ax, dy = e.by - e.ay, dz = e.bz - e.az;
    total += sphere_overlap(std::sqrt(dx * dx + dy * dy + dz * dz), e.ar, e.br).volume;
  }
  t.top = 0;
  const int n = static_cast<int>(w.frontier.size());
  const int wanted = std::min(QueryWorker::kMaxChunks, n);
  int chunks = 0;
  float acc = 0.f;
  w.chunk_begin[0] = 0;
  for (int i = 0; i < n && chunks + 1 < wanted; ++i) {
    const VolumeQuery::StackEntry& e = w.frontier[static_cast<std::size_t>(i)];
    const float dx = e.bx - e.ax, dy = e.by - e.ay, dz = e.bz - e.az;
    acc += sphere_overlap(std::sqrt(dx * dx + dy * dy + dz * dz), e.ar, e.br).volume;
    if (acc >= total * static_cast<float>(chunks + 1) / static_cast<float>(wanted))
      w.chunk_begin[++chunks] = i + 1;
  }
  if (w.chunk_begin[chunks] < n) w.chunk_begin[++chunks] = n;

  // post the run, then take chunks from the front until none is left
  w.traversal =
      detail::make_traversal(a, b, b_in_a, options, &w.stack, w.pairs.data(), nullptr, w.batch.get(), w.moved.get());
  w.traversal.capacity = static_cast<std::int32_t>(w.pairs.size());
  w.traversal.search_margin = t.search_margin;
  w.lanes = lanes;
  w.finished.store(0, std::memory_order_relaxed);
  w.claim.store(static_cast<std::uint32_t>(chunks) << 16, std::memory_order_release);
  w.posted.fetch_add(1, std::memory_order_release);
  wake_one(w.posted);
  if (options.worker_claims_first) {
    while (w.claim.load(std::memory_order_acquire) >> 16 == static_cast<std::uint32_t>(chunks)) {
#if defined(__SSE2__)
      _mm_pause();
#endif
    }
  }
  int mine = 0;
  for (int c = w.claim_front(); c >= 0; c = w.claim_front(), ++mine) {
    t.reserve_stack(static_cast<std::size_t>(w.chunk_begin[c + 1] - w.chunk_begin[c]));
    w.run_chunk(t, c);
  }
  const int theirs = chunks - mine;
  while (w.finished.load(std::memory_order_acquire) != theirs) {
#if defined(__SSE2__)
    _mm_pause();
#endif
  }

  const Traversal& wt = w.traversal;
  if (wt.overlapping + wt.near > wt.stored) {
    // the worker's buffer overflowed, so its pairs cannot all be added: run its chunks again here,
    // after the caller's, which is the one-thread order
    for (int c = mine; c < chunks; ++c) {
      t.reserve_stack(static_cast<std::size_t>(w.chunk_begin[c + 1] - w.chunk_begin[c]));
      w.run_chunk(t, c);
    }
    return 0;
  }
  // the worker's pairs after the caller's, chunk by chunk in frontier order
  for (int c = mine; c < chunks; ++c) {
    const PairOverlap* p = w.pairs.data() + w.chunk_first_pair[c];
    for (const PairOverlap* end = p + w.chunk_pair_count[c]; p != end; ++p) {
      if (p->volume > 0.f) {
        t.add_overlap(p->volume, p->area, p->normal[0], p->normal[1], p->normal[2], p->centroid[0],
                      p->centroid[1], p->centroid[2], p->leaf_a, p->leaf_b);
      } else {
        ++t.near;  // a near pair of the contact margin, stored as the worker stored it
        if (t.stored < t.capacity) t.out[t.stored++] = *p;
      }
    }
  }
  t.visited += wt.visited;
  t.leaf_tests += wt.leaf_tests;
  return theirs;
}

// Fills a result from a finished traversal or candidate test.
void finish(const Traversal& t, bool collect_pairs, VolumeQueryResult& result) {
  result.total_volume = t.sum.volume;
  result.weighted_normal_sum = {t.sum.nx, t.sum.ny, t.sum.nz};
  result.restoring_direction = normalized(result.weighted_normal_sum);
  if (t.sum.volume > 0.0) result.volume_centroid = Vec3{t.sum.cx, t.sum.cy, t.sum.cz} / t.sum.volume;
  result.volume_gradient = -Vec3{t.sum.gx, t.sum.gy, t.sum.gz};
  result.pair_count = t.stored;
  result.truncated = t.overlapping + t.near > t.stored && collect_pairs;
  result.near_pairs = t.near;
  result.stats.node_pairs_visited = t.visited;
  result.stats.leaf_pairs_tested = t.leaf_tests;
  result.stats.overlapping_pairs = t.overlapping;
}

}  // namespace

void VolumeQuery::traverse(const SphereTree& a, const SphereTree& b, const Pose& b_in_a, bool keep_candidates) {
  const bool fast = !keep_candidates && !options_.reference_kernel;
  Traversal t = detail::make_traversal(a, b, b_in_a, options_, &stack_, pairs_.data(), &candidates_, batch_.get(),
                                       fast ? moved_.get() : nullptr);
  if (keep_candidates) {
    t.search_margin += options_.coherence_skin;
    candidates_.clear();
  }

  // the roots: A's and B's root spheres, B's moved into A's frame
  const SphereTreeNode& ra = a.root();
  const SphereTreeNode& rb = b.root();
  float x, y, z;
  t.xf.apply(rb.x, rb.y, rb.z, x, y, z);
  const float dx = x - ra.x, dy = y - ra.y, dz = z - ra.z;
  const float rs = ra.radius + rb.radius + t.search_margin;
  if (ra.is_leaf() && rb.is_leaf()) ++t.leaf_tests;
  if (dx * dx + dy * dy + dz * dz < rs * rs) {
    if (ra.is_leaf() && rb.is_leaf()) {
      if (keep_candidates)
        t.leaf_pair<true>(ra.x, ra.y, ra.z, ra.radius, x, y, z, rb.radius, ra.first, rb.first);
      else
        t.add_pair(ra.x, ra.y, ra.z, ra.radius, x, y, z, rb.radius, ra.first, rb.first);
    } else {
      t.push(t.a.root, t.b.root, ra.x, ra.y, ra.z, ra.radius, x, y, z, rb.radius);
    }
  }
  // one loop per pair of block widths (trees built with arity <= 4 and > 4 can meet)
  const bool wide_a = t.a.width != 4, wide_b = t.b.width != 4;
  if (keep_candidates) {
    if (!wide_a) wide_b ? t.run<4, 8, true>() : t.run<4, 4, true>();
    else wide_b ? t.run<8, 8, true>() : t.run<8, 4, true>();
  } else if (options_.reference_kernel) {
    if (!wide_a) wide_b ? t.run<4, 8, false>() : t.run<4, 4, false>();
    else wide_b ? t.run<8, 8, false>() : t.run<8, 4, false>();
  } else if (worker_) {
    worker_chunks_ = run_shared(*worker_, t, kernel_lanes_, a, b, b_in_a, options_);
  } else {
    detail::run_fast(kernel_lanes_, t);
  }
  finish(t, options_.collect_pairs, result_);
  if (!keep_candidates) return;
  result_.candidate_pairs = static_cast<std::int64_t>(candidates_.size());

  // B's leaves among the candidates get slots, in first-seen order (the traversal's locality)
  const auto leaf_count_b = static_cast<std::size_t>(b.leaf_count());
  if (slot_of_leaf_b_.size() != leaf_count_b) slot_of_leaf_b_.assign(leaf_count_b, -1);
  if (candidate_leaves_b_.capacity() < leaf_count_b) candidate_leaves_b_.reserve(leaf_count_b);
  if (moved_leaves_b_.size() < leaf_count_b) moved_leaves_b_.resize(leaf_count_b);
  candidate_leaves_b_.clear();
  for (Candidate& c : candidates_) {
    std::int32_t& slot = slot_of_leaf_b_[static_cast<std::size_t>(c.slot_b)];
    if (slot < 0) {
      slot = static_cast<std::int32_t>(candidate_leaves_b_.size());
      candidate_leaves_b_.push_back(c.slot_b);
    }
    c.slot_b = slot;
  }
  for (const std::int32_t leaf : candidate_leaves_b_) slot_of_leaf_b_[static_cast<std::size_t>(leaf)] = -1;
  candidate_tree_a_ = &a;
  candidate_tree_b_ = &b;
  candidate_pose_ = b_in_a;
}

bool VolumeQuery::candidates_hold(const SphereTree& a, const SphereTree& b, const Pose& b_in_a) const {
  if (&a != candidate_tree_a_ || &b != candidate_tree_b_) return false;
  // How far any point of B can have moved relative to A since the candidates were kept: B's leaf
  // centres lie within its root sphere (c, R), and x(P1) - x(P0) = (R1 - R0) q + (t1 - t0) with
  // q = c + u, |u| <= R, so |move| <= |P1 c - P0 c| + |R1 - R0| R, where |R1 - R0| = 2 sin(theta/2)
  // for the relative rotation angle theta: twice the vector part of conj(q0) q1.
  const SphereTreeNode& root_b = b.root();
  const SphereTreeNode& root_a = a.root();
  const auto centre = [](const SphereTreeNode& n) {
    return Vec3{static_cast<double>(n.x), static_cast<double>(n.y), static_cast<double>(n.z)};
  };
  const Vec3 c = centre(root_b);
  const Vec3 c_now = transform_point(b_in_a, c);
  const Quat rel = conjugate(normalized(candidate_pose_.rotation)) * normalized(b_in_a.rotation);
  const double sin_half = std::sqrt(rel.x * rel.x + rel.y * rel.y + rel.z * rel.z);
  const double move = norm(c_now - transform_point(candidate_pose_, c)) + 2.0 * sin_half * static_cast<double>(root_b.radius);
  // float round-off of the traversal that kept them, a few ulps of the coordinates' magnitude
  const double scale = norm(c_now) + static_cast<double>(root_b.radius) + norm(centre(root_a)) +
                       static_cast<double>(root_a.radius);
  return std::isfinite(move) && move + 1e-5 * scale < static_cast<double>(options_.coherence_skin);
}

void VolumeQuery::test_candidates(const SphereTree& a, const SphereTree& b, const Pose& b_in_a) {
  Traversal t =
      detail::make_traversal(a, b, b_in_a, options_, &stack_, pairs_.data(), &candidates_, batch_.get());
  // B's candidate leaves moved into A's frame once, with the traversal's float arithmetic (same
  // association as its SIMD transform), so that a pair's distance is bit for bit the traversal's
  const auto leaves_b = b.leaves();
  const detail::FloatTransform& f = t.xf;
  Sphere* moved = moved_leaves_b_.data();
  for (std::size_t i = 0; i < candidate_leaves_b_.size(); ++i) {
    const Sphere& s = leaves_b[static_cast<std::size_t>(candidate_leaves_b_[i])];
    moved[i] = {(f.r[0][0] * s.x + f.r[0][1] * s.y) + (f.r[0][2] * s.z + f.t[0]),
                (f.r[1][0] * s.x + f.r[1][1] * s.y) + (f.r[1][2] * s.z + f.t[1]),
                (f.r[2][0] * s.x + f.r[2][1] * s.y) + (f.r[2][2] * s.z + f.t[2]), s.radius};
  }
  const Sphere* leaves_a = t.leaves_a;
  for (const Candidate& c : candidates_) {
    const Sphere& sa = leaves_a[c.leaf_a];
    const Sphere& sb = moved[c.slot_b];
    const float dx = sb.x - sa.x, dy = sb.y - sa.y, dz = sb.z - sa.z, rs = sb.radius + (sa.radius + t.margin);
    if (dx * dx + dy * dy + dz * dz < rs * rs)
      t.add_pair(sa.x, sa.y, sa.z, sa.radius, sb.x, sb.y, sb.z, sb.radius, c.leaf_a,
                 candidate_leaves_b_[static_cast<std::size_t>(c.slot_b)]);
  }
  t.leaf_tests = static_cast<std::int64_t>(candidates_.size());
  finish(t, options_.collect_pairs, result_);
  result_.candidate_pairs = static_cast<std::int64_t>(candidates_.size());
}

const VolumeQueryResult& VolumeQuery::run(const SphereTree& a, const SphereTree& b, const Pose& b_in_a) {
  assert(!a.empty() && !b.empty() && "uh::collette::VolumeQuery::run(): empty tree");
  result_ = VolumeQueryResult{};
  if (options_.coherence_skin <= 0.f) {
    traverse(a, b, b_in_a, false);
    return result_;
  }
  // a traversal that keeps candidates evaluates the pairs as it goes; later runs test only those
  if (candidates_hold(a, b, b_in_a)) {
    test_candidates(a, b, b_in_a);
    result_.reused_candidates = true;
  } else {
    traverse(a, b, b_in_a, true);
  }
  return result_;
}

void VolumeQuery::run(const SphereTree& a, const SphereTree& b, const Pose& world_from_a, const Pose& world_from_b,
                      ContactFrame& out) {
  const auto start = std::chrono::steady_clock::now();
  out.pair_count = 0;
  out.section_count = 0;
  const ContactSection& s = append_section(a, b, world_from_a, world_from_b, out);
  const VolumeQueryResult& r = result_;
  out.world_from_a = world_from_a;
  out.world_from_b = world_from_b;
  out.total_volume = r.total_volume;
  out.restoring_direction_world = transform_vector(world_from_a, r.restoring_direction);
  out.volume_centroid_world = r.total_volume > 0.0 ? transform_point(world_from_a, r.volume_centroid) : Vec3{};
  out.volume_gradient_world = s.volume_gradient_world;
  out.distance = 0.0;
  out.truncated = s.truncated;
  if (s.pair_count == 0) out.section_count = 0;  // nothing to hold: a frame without pairs has no section
  out.query_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

const ContactSection& VolumeQuery::append_section(const SphereTree& a, const SphereTree& b,
                                                  const Pose& world_from_a, const Pose& world_from_b,
                                                  ContactFrame& out) {
  const Pose b_in_a = inverse(world_from_a) * world_from_b;
  const VolumeQueryResult& r = run(a, b, b_in_a);
  const std::int32_t first = out.pair_count;
  const std::int32_t n = r.pair_count;
  out.resize_pairs(first + n);  // grows the frame (only) when it holds fewer pairs than ever before
  const Mat3 m = rotation_matrix(normalized(world_from_a.rotation));
  const auto leaves_a = a.leaves();
  const auto leaves_b = b.leaves();
  const auto pairs = out.pairs();
  for (std::int32_t i = 0; i < n; ++i) {
    const PairOverlap& p = pairs_[static_cast<std::size_t>(i)];
    SpherePairContact& c = pairs[static_cast<std::size_t>(first + i)];
    c.volume = p.volume;
    c.area = p.area;
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
  return out.add_section({.world_from_a = world_from_a,
                          .world_from_b = world_from_b,
                          .total_volume = r.total_volume,
                          .volume_gradient_world = transform_vector(world_from_a, r.volume_gradient),
                          .first_pair = first,
                          .pair_count = n,
                          .truncated = r.stats.overlapping_pairs + r.near_pairs > n});
}

}  // namespace uh::collette
