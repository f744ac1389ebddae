#include "uh/collette/volume_query.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <chrono>
#include <cmath>
#include <memory>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "leaf_batch.hpp"
#include "query_kernels.hpp"
#include "uh/core/sphere_overlap.hpp"

namespace uh::collette {
namespace {

// Running totals in double: tens of thousands of float pair terms would lose digits otherwise.
struct Totals {
  double volume = 0.0;
  double nx = 0.0, ny = 0.0, nz = 0.0;
  double gx = 0.0, gy = 0.0, gz = 0.0;  // sum of pi a^2 * normal
  double cx = 0.0, cy = 0.0, cz = 0.0;
};

}  // namespace

VolumeQuery::VolumeQuery(const VolumeQueryOptions& options)
    : options_(options), batch_(std::make_unique<detail::LeafBatch>()) {
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

// byte j all ones when bit j of the index is set: spreads a child mask over the 8-bit rows of a
// 64-bit child-pair mask
constexpr auto kByteMask = [] {
  std::array<std::uint64_t, 256> t{};
  for (std::uint32_t m = 0; m < 256; ++m)
    for (int j = 0; j < 8; ++j)
      if ((m >> j) & 1u) t[m] |= std::uint64_t{0xff} << (8 * j);
  return t;
}();

constexpr int popcount8(std::uint32_t m) {
  constexpr int kNibble[16] = {0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4};
  return kNibble[m & 15u] + kNibble[(m >> 4) & 15u];
}

// Everything one traversal reads and writes, so that the width-specialised loop below keeps it in
// registers or one cache line.
struct Traversal {
  SphereTree::Blocks a, b;
  const Sphere* leaves_a;
  detail::FloatTransform xf;
  std::vector<VolumeQuery::StackEntry>* stack;  // storage (size = capacity); entries below `top` are live
  std::size_t top = 0;
  PairOverlap* out;
  std::int32_t capacity;
  float margin;                // pairs closer than this but not overlapping are stored with volume 0
  float search_margin;         // node and leaf pairs closer than this are followed (margin, plus the skin when keeping)
  std::vector<VolumeQuery::Candidate>* candidates;  // keeping traversals: (A leaf, B leaf index) within search_margin
  detail::LeafBatch* batch;  // leaf pairs waiting for the SIMD lens kernel (batched traversals)
  std::int32_t stored = 0;
  std::int64_t overlapping = 0;
  std::int64_t near = 0;       // stored-or-counted pairs within the margin that do not overlap
  std::int64_t leaf_tests = 0;
  std::int64_t visited = 0;
  Totals sum;

  // an overlapping leaf pair: A's leaf la at (ax, ay, az, ar), B's leaf lb at (bx, by, bz, br) in A's frame
  [[gnu::always_inline]] inline void add_pair(float ax, float ay, float az, float ar, float bx, float by, float bz, float br, std::int32_t la,
                std::int32_t lb) {
    const float dx = bx - ax, dy = by - ay, dz = bz - az;
    const float d = std::sqrt(dx * dx + dy * dy + dz * dz);
    const SphereOverlap<float> o = sphere_overlap(d, ar, br);
    const float v = o.volume;
    if (!(v > 0.f)) {
      if (margin > 0.f && d < ar + br + margin) add_near_pair(dx, dy, dz, d, ax, ay, az, ar, la, lb);
      return;
    }
    const float inv = d > 0.f ? 1.f / d : 0.f;
    const float nx = dx * inv, ny = dy * inv, nz = dz * inv;
    add_overlap(v, o.area, nx, ny, nz, ax + nx * o.centroid_offset, ay + ny * o.centroid_offset,
                az + nz * o.centroid_offset, la, lb);
  }

  // an overlapping pair's lens (volume v > 0, disk area, unit normal, centroid) into the totals
  // and the pair buffer
  [[gnu::always_inline]] inline void add_overlap(float v, float area, float nx, float ny, float nz, float cx,
                                                 float cy, float cz, std::int32_t la, std::int32_t lb) {
    const double vd = static_cast<double>(v);
    sum.volume += vd;
    sum.nx += vd * static_cast<double>(nx);
    sum.ny += vd * static_cast<double>(ny);
    sum.nz += vd * static_cast<double>(nz);
    sum.cx += vd * static_cast<double>(cx);
    sum.cy += vd * static_cast<double>(cy);
    sum.cz += vd * static_cast<double>(cz);
    const double ad = static_cast<double>(area);
    sum.gx += ad * static_cast<double>(nx);
    sum.gy += ad * static_cast<double>(ny);
    sum.gz += ad * static_cast<double>(nz);
    ++overlapping;
    if (stored < capacity) {
      PairOverlap& p = out[stored++];
      p.leaf_a = la;
      p.leaf_b = lb;
      p.volume = v;
      p.area = area;
      p.normal[0] = nx;
      p.normal[1] = ny;
      p.normal[2] = nz;
      p.centroid[0] = cx;
      p.centroid[1] = cy;
      p.centroid[2] = cz;
    }
  }

  // a pair apart by less than the margin: stored with volume 0 so that a holder of the pair set
  // (ForceComp's multi-rate re-evaluation) sees it start to overlap before the next query
  void add_near_pair(float dx, float dy, float dz, float d, float ax, float ay, float az, float ar, std::int32_t la,
                     std::int32_t lb) {
    ++near;
    if (stored >= capacity) return;
    const float inv = d > 0.f ? 1.f / d : 0.f;
    PairOverlap& p = out[stored++];
    p.leaf_a = la;
    p.leaf_b = lb;
    p.volume = 0.f;
    p.area = 0.f;
    p.normal[0] = dx * inv;
    p.normal[1] = dy * inv;
    p.normal[2] = dz * inv;
    // where the lens will appear: the point of A's sphere towards B
    p.centroid[0] = ax + p.normal[0] * ar;
    p.centroid[1] = ay + p.normal[1] * ar;
    p.centroid[2] = az + p.normal[2] * ar;
  }

  // Evaluates the batched leaf pairs, in the order they were added (so pairs are stored and
  // summed exactly as the scalar path would), and empties the batch.
  void flush() {
    detail::LeafBatch& lb = *batch;
    lb.pad();
    detail::LensLanes lanes;
#if defined(__SSE2__)
    constexpr int kGroup = 4;
#else
    constexpr int kGroup = 1;
#endif
    for (int i = 0; i < lb.count; i += kGroup) {
      std::uint32_t near_lanes = 0;
#if defined(__SSE2__)
      const std::uint32_t hits = detail::lens_lanes4(lb, i, margin, lanes, near_lanes);
#else
      const std::uint32_t hits = detail::lens_lane1(lb, i, margin, lanes, near_lanes);
#endif
      const std::uint32_t valid = lb.count - i >= kGroup ? (1u << kGroup) - 1u : (1u << (lb.count - i)) - 1u;
      std::uint32_t todo = (hits | near_lanes) & valid;
      while (todo) {
        const int j = std::countr_zero(todo);
        todo &= todo - 1u;
        const int k = i + j;
        if ((hits >> j) & 1u) {
          add_overlap(lanes.volume[j], lanes.area[j], lanes.nx[j], lanes.ny[j], lanes.nz[j], lanes.cx[j],
                      lanes.cy[j], lanes.cz[j], lb.leaf_a[k], lb.leaf_b[k]);
        } else {
          const float dx = lb.bx[k] - lb.ax[k], dy = lb.by[k] - lb.ay[k], dz = lb.bz[k] - lb.az[k];
          add_near_pair(dx, dy, dz, std::sqrt(dx * dx + dy * dy + dz * dz), lb.ax[k], lb.ay[k], lb.az[k],
                        lb.ar[k], lb.leaf_a[k], lb.leaf_b[k]);
        }
      }
    }
    lb.count = 0;
  }

  // bit j set when lane j of the (x, y, z, r) lanes overlaps the sphere (px, py, pz, pr)
  template <int W>
  static std::uint32_t overlap_mask(const float* x, const float* y, const float* z, const float* r, float px, float py,
                                    float pz, float pr) {
    std::uint32_t hits = 0;
#if defined(__SSE2__)
    const __m128 bx = _mm_set1_ps(px), by = _mm_set1_ps(py), bz = _mm_set1_ps(pz), br = _mm_set1_ps(pr);
    for (int k = 0; k < W; k += 4) {
      const __m128 dx = _mm_sub_ps(bx, _mm_loadu_ps(x + k));
      const __m128 dy = _mm_sub_ps(by, _mm_loadu_ps(y + k));
      const __m128 dz = _mm_sub_ps(bz, _mm_loadu_ps(z + k));
      const __m128 rs = _mm_add_ps(br, _mm_loadu_ps(r + k));
      const __m128 d2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
      hits |= static_cast<std::uint32_t>(_mm_movemask_ps(_mm_cmplt_ps(d2, _mm_mul_ps(rs, rs)))) << k;
    }
#else
    for (int k = 0; k < W; ++k) {
      const float dx = px - x[k], dy = py - y[k], dz = pz - z[k], rs = pr + r[k];
      hits |= (dx * dx + dy * dy + dz * dz < rs * rs ? 1u : 0u) << k;
    }
#endif
    return hits;
  }

  // B's children of block kb moved into A's frame: t[0..W) x, t[W..2W) y, t[2W..3W) z, t[3W..4W) r
  template <int W>
  void transform_block(std::int32_t kb, float* t) const {
    const float* src = b.bounds + static_cast<std::size_t>(kb) * 4 * W;
#if defined(__SSE2__)
    const __m128 r00 = _mm_set1_ps(xf.r[0][0]), r01 = _mm_set1_ps(xf.r[0][1]), r02 = _mm_set1_ps(xf.r[0][2]);
    const __m128 r10 = _mm_set1_ps(xf.r[1][0]), r11 = _mm_set1_ps(xf.r[1][1]), r12 = _mm_set1_ps(xf.r[1][2]);
    const __m128 r20 = _mm_set1_ps(xf.r[2][0]), r21 = _mm_set1_ps(xf.r[2][1]), r22 = _mm_set1_ps(xf.r[2][2]);
    const __m128 t0 = _mm_set1_ps(xf.t[0]), t1 = _mm_set1_ps(xf.t[1]), t2 = _mm_set1_ps(xf.t[2]);
    for (int k = 0; k < W; k += 4) {
      const __m128 x = _mm_loadu_ps(src + k), y = _mm_loadu_ps(src + W + k), z = _mm_loadu_ps(src + 2 * W + k);
      _mm_storeu_ps(t + k, _mm_add_ps(_mm_add_ps(_mm_mul_ps(r00, x), _mm_mul_ps(r01, y)), _mm_add_ps(_mm_mul_ps(r02, z), t0)));
      _mm_storeu_ps(t + W + k, _mm_add_ps(_mm_add_ps(_mm_mul_ps(r10, x), _mm_mul_ps(r11, y)), _mm_add_ps(_mm_mul_ps(r12, z), t1)));
      _mm_storeu_ps(t + 2 * W + k, _mm_add_ps(_mm_add_ps(_mm_mul_ps(r20, x), _mm_mul_ps(r21, y)), _mm_add_ps(_mm_mul_ps(r22, z), t2)));
      _mm_storeu_ps(t + 3 * W + k, _mm_loadu_ps(src + 3 * W + k));
    }
#else
    for (int k = 0; k < W; ++k) xf.apply(src[k], src[W + k], src[2 * W + k], t[k], t[W + k], t[2 * W + k]);
    for (int k = 0; k < W; ++k) t[3 * W + k] = src[3 * W + k];
#endif
  }

  // a node pair: A's node sphere (ax, ay, az, ar) and B's (bx, by, bz, br), both in A's frame
  void push(std::int32_t ia, std::int32_t ib, float ax, float ay, float az, float ar, float bx, float by,
            float bz, float br) {
    (*stack)[top++] = {ia, ib, ax, ay, az, ar, bx, by, bz, br};
  }

  // A pushed pair's blocks (or A's leaf sphere) into the cache, so that its visit does not wait for
  // them: each visit's loads depend on the visit before, and without the prefetch the traversal is
  // bound by that latency rather than by its arithmetic.
  template <int WA, int WB>
  void push_prefetched(std::int32_t ia, std::int32_t ib, float ax, float ay, float az, float ar, float bx,
                       float by, float bz, float br) {
#if defined(__SSE2__)
    if (ia >= 0) {
      const char* pa = reinterpret_cast<const char*>(a.bounds + static_cast<std::size_t>(ia) * 4 * WA);
      _mm_prefetch(pa, _MM_HINT_T0);
      if constexpr (WA == 8) _mm_prefetch(pa + 64, _MM_HINT_T0);
    } else {
      _mm_prefetch(reinterpret_cast<const char*>(leaves_a + ~ia), _MM_HINT_T0);
    }
    if (ib >= 0) {
      const char* pb = reinterpret_cast<const char*>(b.bounds + static_cast<std::size_t>(ib) * 4 * WB);
      _mm_prefetch(pb, _MM_HINT_T0);
      if constexpr (WB == 8) _mm_prefetch(pb + 64, _MM_HINT_T0);
    }
#endif
    push(ia, ib, ax, ay, az, ar, bx, by, bz, br);
  }

  // room for n more entries (grows, rarely, outside steady state)
  void reserve_stack(std::size_t n) {
    if (stack->size() - top < n) stack->resize(2 * stack->size() + n);
  }

  // a leaf pair within search_margin: evaluated now, or kept as a candidate (B's leaf by index;
  // VolumeQuery::traverse turns it into a slot); grows only past every earlier run's need
  template <bool Keep>
  [[gnu::always_inline]] inline void leaf_pair(float ax, float ay, float az, float ar, float bx, float by,
                                               float bz, float br, std::int32_t la, std::int32_t lb) {
    if constexpr (Keep) {
      if (candidates->size() == candidates->capacity()) candidates->reserve(2 * candidates->capacity() + 1024);
      candidates->push_back({la, lb});
      // the same test as VolumeQuery::test_candidates, so that both give the same pairs
      const float dx = bx - ax, dy = by - ay, dz = bz - az, rs = br + (ar + margin);
      if (dx * dx + dy * dy + dz * dz < rs * rs) add_pair(ax, ay, az, ar, bx, by, bz, br, la, lb);
    } else {
      add_pair(ax, ay, az, ar, bx, by, bz, br, la, lb);
    }
  }

  // The reference traversal (and the keeping one): one pair at a time with the scalar kernel, the
  // hits of every child handled as they come.
  template <int WA, int WB, bool Keep>
  void run() {
    alignas(16) float tb[4 * WB];
    while (top > 0) {
      const VolumeQuery::StackEntry e = (*stack)[--top];
      ++visited;
      // grow (rarely, outside steady state) before a batch of up to WA * WB pushes
      reserve_stack(static_cast<std::size_t>(WA * WB));
      if (e.a < 0) {
        // A is a leaf: B's children against it
        const Sphere& s = leaves_a[~e.a];
        transform_block<WB>(e.b, tb);
        const std::uint32_t count_b = b.count[e.b];
        const std::uint32_t leaf_b = b.leaf_mask[e.b];
        std::uint32_t hits = overlap_mask<WB>(tb, tb + WB, tb + 2 * WB, tb + 3 * WB, s.x, s.y, s.z, s.radius + search_margin) & ((1u << count_b) - 1u);
        leaf_tests += popcount8(leaf_b);
        const std::int32_t* cb = b.child + static_cast<std::size_t>(e.b) * WB;
        while (hits) {
          const int j = std::countr_zero(hits);
          hits &= hits - 1u;
          if ((leaf_b >> j) & 1u)
            leaf_pair<Keep>(s.x, s.y, s.z, s.radius, tb[j], tb[WB + j], tb[2 * WB + j], tb[3 * WB + j], ~e.a,
                            ~cb[j]);
          else
            push(e.a, cb[j], e.ax, e.ay, e.az, e.ar, tb[j], tb[WB + j], tb[2 * WB + j], tb[3 * WB + j]);
        }
        continue;
      }
      const float* ab = a.bounds + static_cast<std::size_t>(e.a) * 4 * WA;
      const std::int32_t* ca = a.child + static_cast<std::size_t>(e.a) * WA;
      const std::uint32_t leaf_a = a.leaf_mask[e.a];
      if (e.b < 0) {
        // B is a leaf: A's children against it (padding lanes of A never overlap)
        std::uint32_t hits = overlap_mask<WA>(ab, ab + WA, ab + 2 * WA, ab + 3 * WA, e.bx, e.by, e.bz, e.br + search_margin);
        leaf_tests += popcount8(leaf_a);
        while (hits) {
          const int k = std::countr_zero(hits);
          hits &= hits - 1u;
          if ((leaf_a >> k) & 1u)
            leaf_pair<Keep>(ab[k], ab[WA + k], ab[2 * WA + k], ab[3 * WA + k], e.bx, e.by, e.bz, e.br, ~ca[k],
                            ~e.b);
          else
            push(ca[k], e.b, ab[k], ab[WA + k], ab[2 * WA + k], ab[3 * WA + k], e.bx, e.by, e.bz, e.br);
        }
        continue;
      }
      // both inner: every child of B (moved once) against all children of A in one batch
      transform_block<WB>(e.b, tb);
      const int count_b = b.count[e.b];
      const std::uint32_t leaf_b = b.leaf_mask[e.b];
      const std::int32_t* cb = b.child + static_cast<std::size_t>(e.b) * WB;
      leaf_tests += popcount8(leaf_a) * popcount8(leaf_b);
      for (int j = 0; j < count_b; ++j) {
        std::uint32_t hits = overlap_mask<WA>(ab, ab + WA, ab + 2 * WA, ab + 3 * WA, tb[j], tb[WB + j], tb[2 * WB + j], tb[3 * WB + j] + search_margin);
        const bool b_leaf = (leaf_b >> j) & 1u;
        while (hits) {
          const int k = std::countr_zero(hits);
          hits &= hits - 1u;
          if (b_leaf && ((leaf_a >> k) & 1u))
            leaf_pair<Keep>(ab[k], ab[WA + k], ab[2 * WA + k], ab[3 * WA + k], tb[j], tb[WB + j],
                            tb[2 * WB + j], tb[3 * WB + j], ~ca[k], ~cb[j]);
          else
            push(ca[k], cb[j], ab[k], ab[WA + k], ab[2 * WA + k], ab[3 * WA + k], tb[j], tb[WB + j],
                 tb[2 * WB + j], tb[3 * WB + j]);
        }
      }
    }
  }

  // The fast traversal: the same node pairs in the same order, and the same leaf pairs, but each
  // visit first tests all its child pairs into one mask (8 bits per child of B), then appends
  // the leaf pairs among the hits to the batch and pushes the rest, in two loops without
  // data-dependent branches in their bodies (the reference's branch per hit mispredicted about
  // once per hit). Leaf pairs are evaluated a SIMD group at a time by flush(). Within a visit,
  // both the leaf pairs and the pushes come in the reference's (child of B, child of A) order, so
  // pairs are found, stored and summed in the same order: the results are identical.
  template <int WA, int WB>
  void run_fast() {
    static_assert(WA <= 8 && WB <= 8);
    alignas(16) float tb[4 * WB];
    detail::LeafBatch& lb = *batch;
    while (top > 0) {
      if (lb.count > detail::LeafBatch::kCapacity - WA * WB) flush();
      const VolumeQuery::StackEntry e = (*stack)[--top];
      ++visited;
      reserve_stack(static_cast<std::size_t>(WA * WB));
      if (e.a < 0) {
        // A is a leaf: B's children against it
        const Sphere& s = leaves_a[~e.a];
        transform_block<WB>(e.b, tb);
        const std::uint32_t leaf_b = b.leaf_mask[e.b];
        const std::uint32_t hits =
            overlap_mask<WB>(tb, tb + WB, tb + 2 * WB, tb + 3 * WB, s.x, s.y, s.z, s.radius + search_margin) &
            ((1u << b.count[e.b]) - 1u);
        leaf_tests += popcount8(leaf_b);
        const std::int32_t* cb = b.child + static_cast<std::size_t>(e.b) * WB;
        for (std::uint32_t m = hits & leaf_b; m; m &= m - 1u) {
          const int j = std::countr_zero(m);
          lb.add(s.x, s.y, s.z, s.radius, tb[j], tb[WB + j], tb[2 * WB + j], tb[3 * WB + j], ~e.a, ~cb[j]);
        }
        for (std::uint32_t m = hits & ~leaf_b; m; m &= m - 1u) {
          const int j = std::countr_zero(m);
          push_prefetched<WA, WB>(e.a, cb[j], e.ax, e.ay, e.az, e.ar, tb[j], tb[WB + j], tb[2 * WB + j],
                                  tb[3 * WB + j]);
        }
        continue;
      }
      const float* ab = a.bounds + static_cast<std::size_t>(e.a) * 4 * WA;
      const std::int32_t* ca = a.child + static_cast<std::size_t>(e.a) * WA;
      const std::uint32_t leaf_a = a.leaf_mask[e.a];
      if (e.b < 0) {
        // B is a leaf: A's children against it (padding lanes of A never overlap)
        const std::uint32_t hits =
            overlap_mask<WA>(ab, ab + WA, ab + 2 * WA, ab + 3 * WA, e.bx, e.by, e.bz, e.br + search_margin);
        leaf_tests += popcount8(leaf_a);
        for (std::uint32_t m = hits & leaf_a; m; m &= m - 1u) {
          const int k = std::countr_zero(m);
          lb.add(ab[k], ab[WA + k], ab[2 * WA + k], ab[3 * WA + k], e.bx, e.by, e.bz, e.br, ~ca[k], ~e.b);
        }
        for (std::uint32_t m = hits & ~leaf_a; m; m &= m - 1u) {
          const int k = std::countr_zero(m);
          push_prefetched<WA, WB>(ca[k], e.b, ab[k], ab[WA + k], ab[2 * WA + k], ab[3 * WA + k], e.bx, e.by,
                                  e.bz, e.br);
        }
        continue;
      }
      // both inner: every child of B (moved once) against all children of A; bit 8 j + k of the
      // mask is child j of B against child k of A
      transform_block<WB>(e.b, tb);
      const std::uint32_t leaf_b = b.leaf_mask[e.b];
      const std::int32_t* cb = b.child + static_cast<std::size_t>(e.b) * WB;
      leaf_tests += popcount8(leaf_a) * popcount8(leaf_b);
      // only B's children that reach A's node sphere can reach a leaf below A: one test of all of
      // them against it saves the row of tests of each that does not (a third to a half of them)
      std::uint64_t hits = 0;
      for (std::uint32_t m = overlap_mask<WB>(tb, tb + WB, tb + 2 * WB, tb + 3 * WB, e.ax, e.ay, e.az,
                                              e.ar + search_margin) &
                             ((1u << b.count[e.b]) - 1u);
           m; m &= m - 1u) {
        const int j = std::countr_zero(m);
        hits |= static_cast<std::uint64_t>(overlap_mask<WA>(ab, ab + WA, ab + 2 * WA, ab + 3 * WA, tb[j],
                                                            tb[WB + j], tb[2 * WB + j],
                                                            tb[3 * WB + j] + search_margin))
                << (8 * j);
      }
      const std::uint64_t leaf_pairs =
          hits & kByteMask[leaf_b] & (static_cast<std::uint64_t>(leaf_a) * 0x0101010101010101ull);
      for (std::uint64_t m = leaf_pairs; m; m &= m - 1u) {
        const int bit = std::countr_zero(m), j = bit >> 3, k = bit & 7;
        lb.add(ab[k], ab[WA + k], ab[2 * WA + k], ab[3 * WA + k], tb[j], tb[WB + j], tb[2 * WB + j],
               tb[3 * WB + j], ~ca[k], ~cb[j]);
      }
      for (std::uint64_t m = hits & ~leaf_pairs; m; m &= m - 1u) {
        const int bit = std::countr_zero(m), j = bit >> 3, k = bit & 7;
        push_prefetched<WA, WB>(ca[k], cb[j], ab[k], ab[WA + k], ab[2 * WA + k], ab[3 * WA + k], tb[j],
                                tb[WB + j], tb[2 * WB + j], tb[3 * WB + j]);
      }
    }
    flush();
  }
};

Traversal make_traversal(const SphereTree& a, const SphereTree& b, const Pose& b_in_a,
                         const VolumeQueryOptions& options, std::vector<VolumeQuery::StackEntry>* stack,
                         PairOverlap* pairs, std::vector<VolumeQuery::Candidate>* candidates,
                         detail::LeafBatch* batch) {
  const float margin = std::max(0.f, options.contact_margin);
  return Traversal{a.blocks(),
                   b.blocks(),
                   a.leaves().data(),
                   detail::FloatTransform::from(b_in_a),
                   stack,
                   0,
                   pairs,
                   options.collect_pairs ? options.pair_capacity : 0,
                   margin,
                   margin,
                   candidates,
                   batch,
                   0,
                   0,
                   0,
                   0,
                   0,
                   Totals{}};
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
  Traversal t = make_traversal(a, b, b_in_a, options_, &stack_, pairs_.data(), &candidates_, batch_.get());
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
  } else {
    if (!wide_a)
      wide_b ? t.run_fast<4, 8>() : t.run_fast<4, 4>();
    else
      wide_b ? t.run_fast<8, 8>() : t.run_fast<8, 4>();
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
  Traversal t = make_traversal(a, b, b_in_a, options_, &stack_, pairs_.data(), &candidates_, batch_.get());
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
