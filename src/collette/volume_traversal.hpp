#pragma once
// The state of one volume-query traversal and the paths that share it (private to Collette).
//
// VolumeQuery runs one of three traversals over the same state: the reference path (Traversal::run,
// one pair at a time with the scalar lens kernel, also the coherence path that keeps candidates),
// and the fast path (volume_fast_path.inl: hit masks per visit, batched SIMD lens kernel), which is
// compiled three times, for the baseline ISA (sse2::run_fast), for AVX2 (avx2::run_fast) and for
// AVX-512 (avx512::run_fast), the widest the CPU has chosen at run time. All give the same pairs in
// the same order, bit for bit.

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "leaf_batch.hpp"
#include "query_kernels.hpp"
#include "uh/collette/volume_query.hpp"
#include "uh/core/sphere_overlap.hpp"

namespace uh::collette::detail {

// Running totals in double: tens of thousands of float pair terms would lose digits otherwise.
struct Totals {
  double volume = 0.0;
  double nx = 0.0, ny = 0.0, nz = 0.0;
  double gx = 0.0, gy = 0.0, gz = 0.0;  // sum of pi a^2 * normal
  double cx = 0.0, cy = 0.0, cz = 0.0;
};

// A stack entry stored and loaded as three 16-byte pieces. The visit after a push usually pops the
// entry just pushed; when a load spans two stores of it (the compiler's own copy stores the ids,
// then the spheres, then the rows, and loads 16 bytes at a time), it cannot be forwarded from them
// and waits until they reach the cache.
static_assert(sizeof(VolumeQuery::StackEntry) == 48);
[[gnu::always_inline]] inline void store_entry(VolumeQuery::StackEntry* p, std::int32_t ia, std::int32_t ib, float ax,
                                               float ay, float az, float ar, float bx, float by, float bz, float br,
                                               std::uint32_t rows) {
#if defined(__SSE2__)
  const auto i = [](float x) { return std::bit_cast<std::int32_t>(x); };
  __m128i* q = reinterpret_cast<__m128i*>(p);
  _mm_storeu_si128(q, _mm_setr_epi32(ia, ib, i(ax), i(ay)));
  _mm_storeu_si128(q + 1, _mm_castps_si128(_mm_setr_ps(az, ar, bx, by)));
  _mm_storeu_si128(q + 2, _mm_setr_epi32(i(bz), i(br), static_cast<std::int32_t>(rows), 0));
#else
  *p = {ia, ib, ax, ay, az, ar, bx, by, bz, br, rows};
#endif
}
[[gnu::always_inline]] inline VolumeQuery::StackEntry load_entry(const VolumeQuery::StackEntry* p) {
  VolumeQuery::StackEntry e;
#if defined(__SSE2__)
  const __m128i* q = reinterpret_cast<const __m128i*>(p);
  __m128i* r = reinterpret_cast<__m128i*>(&e);
  _mm_storeu_si128(r, _mm_loadu_si128(q));
  _mm_storeu_si128(r + 1, _mm_loadu_si128(q + 1));
  _mm_storeu_si128(r + 2, _mm_loadu_si128(q + 2));
#else
  e = *p;
#endif
  return e;
}

// The totals while the fast path sums a batch's pairs: the doubles of Totals, two to a register,
// each updated by the operations add_overlap() performs on it (a product of two floats widened to
// double, then one add), so every sum is bit for bit add_overlap()'s. A pair comes as a row of
// eight floats: volume, area, nx, ny, nz, cx, cy, cz (PairOverlap's order from its volume on).
struct PairSums {
#if defined(__SSE2__)
  __m128d volume, nxy, nz_cx, cyz, gxy, gz;  // volume and gz: the low lane

  explicit PairSums(const Totals& s)
      : volume(_mm_set_sd(s.volume)),
        nxy(_mm_setr_pd(s.nx, s.ny)),
        nz_cx(_mm_setr_pd(s.nz, s.cx)),
        cyz(_mm_setr_pd(s.cy, s.cz)),
        gxy(_mm_setr_pd(s.gx, s.gy)),
        gz(_mm_set_sd(s.gz)) {}

  // two floats of the row, widened
  [[gnu::always_inline]] static __m128d widened(const float* p) {
    return _mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p))));
  }
  [[gnu::always_inline]] void add(const float* row) {
    const __m128d vd = _mm_set1_pd(static_cast<double>(row[0]));
    const __m128d ad = _mm_set1_pd(static_cast<double>(row[1]));
    const __m128d n_xy = widened(row + 2), n_z_c_x = widened(row + 4), c_yz = widened(row + 6);
    volume = _mm_add_sd(volume, vd);
    nxy = _mm_add_pd(nxy, _mm_mul_pd(vd, n_xy));
    nz_cx = _mm_add_pd(nz_cx, _mm_mul_pd(vd, n_z_c_x));
    cyz = _mm_add_pd(cyz, _mm_mul_pd(vd, c_yz));
    gxy = _mm_add_pd(gxy, _mm_mul_pd(ad, n_xy));
    gz = _mm_add_sd(gz, _mm_mul_sd(ad, n_z_c_x));
  }
  void store(Totals& s) const {
    s.volume = _mm_cvtsd_f64(volume);
    _mm_storel_pd(&s.nx, nxy);
    _mm_storeh_pd(&s.ny, nxy);
    _mm_storel_pd(&s.nz, nz_cx);
    _mm_storeh_pd(&s.cx, nz_cx);
    _mm_storel_pd(&s.cy, cyz);
    _mm_storeh_pd(&s.cz, cyz);
    _mm_storel_pd(&s.gx, gxy);
    _mm_storeh_pd(&s.gy, gxy);
    s.gz = _mm_cvtsd_f64(gz);
  }
#else
  Totals sum;
  explicit PairSums(const Totals& s) : sum(s) {}
  void add(const float* row) {
    const double vd = static_cast<double>(row[0]), ad = static_cast<double>(row[1]);
    sum.volume += vd;
    sum.nx += vd * static_cast<double>(row[2]);
    sum.ny += vd * static_cast<double>(row[3]);
    sum.nz += vd * static_cast<double>(row[4]);
    sum.cx += vd * static_cast<double>(row[5]);
    sum.cy += vd * static_cast<double>(row[6]);
    sum.cz += vd * static_cast<double>(row[7]);
    sum.gx += ad * static_cast<double>(row[2]);
    sum.gy += ad * static_cast<double>(row[3]);
    sum.gz += ad * static_cast<double>(row[4]);
  }
  void store(Totals& s) const { s = sum; }
#endif
};

// byte j all ones when bit j of the index is set: spreads a child mask over the 8-bit rows of a
// 64-bit child-pair mask
inline constexpr auto kByteMask = [] {
  std::array<std::uint64_t, 256> t{};
  for (std::uint32_t m = 0; m < 256; ++m)
    for (int j = 0; j < 8; ++j)
      if ((m >> j) & 1u) t[m] |= std::uint64_t{0xff} << (8 * j);
  return t;
}();

// the first four set bits of a child mask, a byte each from the lowest, the first repeated where
// fewer are set (0 when none)
inline constexpr auto kRowList = [] {
  std::array<std::uint32_t, 256> t{};
  for (std::uint32_t m = 0; m < 256; ++m) {
    std::uint32_t list = 0, first = 0;
    int n = 0;
    for (std::uint32_t j = 0; j < 8 && n < 4; ++j)
      if ((m >> j) & 1u) {
        if (n == 0) first = j;
        list |= j << (8 * n++);
      }
    for (; n < 4; ++n) list |= first << (8 * n);
    t[m] = list;
  }
  return t;
}();

// number of bits set in a child mask (popcount is not in the baseline ISA)
inline constexpr auto kBitCount = [] {
  std::array<std::uint8_t, 256> t{};
  for (std::uint32_t m = 0; m < 256; ++m) t[m] = static_cast<std::uint8_t>(std::popcount(m));
  return t;
}();

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
  float margin;         // pairs closer than this but not overlapping are stored with volume 0
  float search_margin;  // node and leaf pairs closer than this are followed (margin, plus the skin when
                        // keeping)
  std::vector<VolumeQuery::Candidate>*
      candidates;            // keeping traversals: (A leaf, B leaf index) within search_margin
  detail::LeafBatch* batch;  // leaf pairs waiting for the SIMD lens kernel (batched traversals)
  detail::MovedBlocks* moved;  // B's blocks moved into A's frame, begun for this run (fast path)
  std::int32_t stored = 0;
  std::int64_t overlapping = 0;
  std::int64_t near = 0;  // stored-or-counted pairs within the margin that do not overlap
  std::int64_t leaf_tests = 0;
  std::int64_t visited = 0;
  Totals sum;

  // an overlapping leaf pair: A's leaf la at (ax, ay, az, ar), B's leaf lb at (bx, by, bz, br) in A's frame
  [[gnu::always_inline]] inline void add_pair(float ax, float ay, float az, float ar, float bx, float by,
                                              float bz, float br, std::int32_t la, std::int32_t lb) {
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

  // add_overlap() for a pair as a row of eight floats (PairSums), summed into `sums`
  [[gnu::always_inline]] inline void add_overlap_row(PairSums& sums, const float* row, std::int32_t la,
                                                     std::int32_t lb) {
    static_assert(offsetof(PairOverlap, area) == offsetof(PairOverlap, volume) + 4 &&
                  offsetof(PairOverlap, normal) == offsetof(PairOverlap, volume) + 8 &&
                  offsetof(PairOverlap, centroid) == offsetof(PairOverlap, volume) + 20 &&
                  sizeof(PairOverlap) == offsetof(PairOverlap, volume) + 32);
    sums.add(row);
    ++overlapping;
    if (stored < capacity) {
      PairOverlap& p = out[stored++];
      p.leaf_a = la;
      p.leaf_b = lb;
      std::memcpy(reinterpret_cast<char*>(&p) + offsetof(PairOverlap, volume), row, 8 * sizeof(float));
    }
  }

  // a pair apart by less than the margin: stored with volume 0 so that a holder of the pair set
  // (ForceComp's multi-rate re-evaluation) sees it start to overlap before the next query
  void add_near_pair(float dx, float dy, float dz, float d, float ax, float ay, float az, float ar,
                     std::int32_t la, std::int32_t lb) {
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

  // bit j set when lane j of the (x, y, z, r) lanes overlaps the sphere (px, py, pz, pr)
  template <int W>
  static std::uint32_t overlap_mask(const float* x, const float* y, const float* z, const float* r, float px,
                                    float py, float pz, float pr) {
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
      const __m128 x = _mm_loadu_ps(src + k), y = _mm_loadu_ps(src + W + k),
                   z = _mm_loadu_ps(src + 2 * W + k);
      _mm_storeu_ps(t + k, _mm_add_ps(_mm_add_ps(_mm_mul_ps(r00, x), _mm_mul_ps(r01, y)),
                                      _mm_add_ps(_mm_mul_ps(r02, z), t0)));
      _mm_storeu_ps(t + W + k, _mm_add_ps(_mm_add_ps(_mm_mul_ps(r10, x), _mm_mul_ps(r11, y)),
                                          _mm_add_ps(_mm_mul_ps(r12, z), t1)));
      _mm_storeu_ps(t + 2 * W + k, _mm_add_ps(_mm_add_ps(_mm_mul_ps(r20, x), _mm_mul_ps(r21, y)),
                                              _mm_add_ps(_mm_mul_ps(r22, z), t2)));
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
  [[gnu::always_inline]] inline void prefetch_pair(std::int32_t ia, std::int32_t ib) const {
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
#else
    (void)ia;
    (void)ib;
#endif
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
      if (candidates->size() == candidates->capacity())
        candidates->reserve(2 * candidates->capacity() + 1024);
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
        std::uint32_t hits =
            overlap_mask<WB>(tb, tb + WB, tb + 2 * WB, tb + 3 * WB, s.x, s.y, s.z, s.radius + search_margin) &
            ((1u << count_b) - 1u);
        leaf_tests += kBitCount[leaf_b];
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
        std::uint32_t hits =
            overlap_mask<WA>(ab, ab + WA, ab + 2 * WA, ab + 3 * WA, e.bx, e.by, e.bz, e.br + search_margin);
        leaf_tests += kBitCount[leaf_a];
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
      leaf_tests += kBitCount[leaf_a] * kBitCount[leaf_b];
      for (int j = 0; j < count_b; ++j) {
        std::uint32_t hits = overlap_mask<WA>(ab, ab + WA, ab + 2 * WA, ab + 3 * WA, tb[j], tb[WB + j],
                                              tb[2 * WB + j], tb[3 * WB + j] + search_margin);
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
};

inline Traversal make_traversal(const SphereTree& a, const SphereTree& b, const Pose& b_in_a,
                                const VolumeQueryOptions& options,
                                std::vector<VolumeQuery::StackEntry>* stack, PairOverlap* pairs,
                                std::vector<VolumeQuery::Candidate>* candidates, detail::LeafBatch* batch,
                                detail::MovedBlocks* moved = nullptr) {
  const float margin = std::max(0.f, options.contact_margin);
  if (moved) moved->begin(b.blocks().size, b.blocks().width);
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
                   moved,
                   0,
                   0,
                   0,
                   0,
                   0,
                   Totals{}};
}

// The fast path for the baseline ISA (volume_query.cpp), for AVX2 (volume_query_avx2.cpp) and for
// AVX-512 (volume_query_avx512.cpp):
// run_fast() traverses until the stack is empty; expand() traverses (in the same order) only until
// the stack holds `entries` node pairs, the frontier that a two-thread query shares out. Both
// evaluate the leaf pairs found so far before they return.
namespace sse2 {
void run_fast(Traversal& t);
void expand(Traversal& t, std::size_t entries);
}  // namespace sse2
namespace avx2 {
/// True when this build has the AVX2 path and the CPU running it supports AVX2.
bool supported();
/// Only when supported().
void run_fast(Traversal& t);
void expand(Traversal& t, std::size_t entries);
}  // namespace avx2
namespace avx512 {
/// True when this build has the AVX-512 path and the CPU running it supports AVX-512 F, VL, DQ, BW.
bool supported();
/// True when the CPU is one whose 512-bit code the default takes (AMD's: they run it at the clock
/// of narrower code; Intel's lower the clock for it, and the 8-lane kernels measured faster there).
bool preferred();
/// Only when supported().
void run_fast(Traversal& t);
void expand(Traversal& t, std::size_t entries);
}  // namespace avx512

/// The fast path at a kernel width (16, 8 or 4 lanes: VolumeQuery::kernel_lanes()).
inline void run_fast(int lanes, Traversal& t) {
  lanes == 16 ? avx512::run_fast(t) : lanes == 8 ? avx2::run_fast(t) : sse2::run_fast(t);
}
inline void expand(int lanes, Traversal& t, std::size_t entries) {
  lanes == 16 ? avx512::expand(t, entries) : lanes == 8 ? avx2::expand(t, entries) : sse2::expand(t, entries);
}

}  // namespace uh::collette::detail
