#pragma once
// Batched leaf pairs of the volume query (private to Collette).
//
// The traversal appends the leaf pairs whose spheres may overlap to a LeafBatch (structure of
// arrays, B's sphere already in A's frame) and evaluates them a SIMD group at a time with
// lens_lanes(): the same float operations, in the same order, as uh::sphere_overlap<float> and
// the scalar pair evaluation of VolumeQuery, so every lane is bit for bit the scalar result (IEEE
// add, mul, div and sqrt are correctly rounded in every lane, and the build does not contract
// a * b + c into fused multiply-adds). The caller then walks the lanes in order, so pairs are
// stored and summed in the scalar order too: the totals are identical, not merely close.

#include <cmath>
#include <cstdint>
#include <limits>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "uh/core/sphere_overlap.hpp"

namespace uh::collette::detail {

/// Leaf pairs waiting for evaluation. Lanes past `count` up to the next multiple of 8 are zero
/// spheres at the origin (apart: never overlap), so a group may read them.
struct LeafBatch {
  static constexpr int kCapacity = 256;
  static constexpr int kPad = 8;
  alignas(32) float ax[kCapacity + kPad], ay[kCapacity + kPad], az[kCapacity + kPad], ar[kCapacity + kPad];
  alignas(32) float bx[kCapacity + kPad], by[kCapacity + kPad], bz[kCapacity + kPad], br[kCapacity + kPad];
  std::int32_t leaf_a[kCapacity], leaf_b[kCapacity];
  int count = 0;

  [[gnu::always_inline]] inline void add(float xa, float ya, float za, float ra, float xb, float yb, float zb, float rb,
                                         std::int32_t la, std::int32_t lb) {
    const int i = count++;
    ax[i] = xa;
    ay[i] = ya;
    az[i] = za;
    ar[i] = ra;
    bx[i] = xb;
    by[i] = yb;
    bz[i] = zb;
    br[i] = rb;
    leaf_a[i] = la;
    leaf_b[i] = lb;
  }

  /// Zero spheres from `count` up to the next multiple of 8.
  void pad() {
    for (int i = count; i < ((count + kPad - 1) / kPad) * kPad; ++i) ax[i] = ay[i] = az[i] = ar[i] = bx[i] = by[i] = bz[i] = br[i] = 0.f;
  }
};

/// What lens_lanes() computes per lane, in A's frame: lens volume (0 unless the spheres overlap),
/// intersection disk area, unit normal from A's centre to B's, lens centroid.
struct LensLanes {
  alignas(32) float volume[8], area[8], nx[8], ny[8], nz[8], cx[8], cy[8], cz[8];
};

inline constexpr float kPiF = static_cast<float>(3.14159265358979323846264338327950288L);
// the constants sphere_overlap<float> folds: (4/3) pi, pi/3
inline constexpr float kFourThirdsPiF = 4.f / 3.f * kPiF;
inline constexpr float kPiThirdF = kPiF / 3.f;

#if defined(__SSE2__)
/// Lanes i .. i+3 of `b` into `out` (lanes 0..3); returns the lanes that overlap (bit j: lane
/// i + j) and, in `near`, those apart by less than `margin` (only when margin > 0).
[[gnu::always_inline]] inline std::uint32_t lens_lanes4(const LeafBatch& b, int i, float margin, LensLanes& out,
                                                        std::uint32_t& near) {
  const __m128 ax = _mm_load_ps(b.ax + i), ay = _mm_load_ps(b.ay + i), az = _mm_load_ps(b.az + i), ar = _mm_load_ps(b.ar + i);
  const __m128 bx = _mm_load_ps(b.bx + i), by = _mm_load_ps(b.by + i), bz = _mm_load_ps(b.bz + i), br = _mm_load_ps(b.br + i);
  const __m128 zero = _mm_setzero_ps();
  const __m128 dx = _mm_sub_ps(bx, ax), dy = _mm_sub_ps(by, ay), dz = _mm_sub_ps(bz, az);
  const __m128 d = _mm_sqrt_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz)));
  const __m128 sum = _mm_add_ps(ar, br);
  const __m128 touching = _mm_cmplt_ps(d, sum);
  const __m128 delta = _mm_sub_ps(ar, br);
  const __m128 rmin = _mm_min_ps(br, ar);  // std::min(ar, br): br < ar ? br : ar
  const __m128 contained = _mm_mul_ps(_mm_mul_ps(_mm_mul_ps(_mm_set1_ps(kFourThirdsPiF), rmin), rmin), rmin);
  const __m128 abs_delta = _mm_andnot_ps(_mm_set1_ps(-0.f), delta);
  const __m128 containment = _mm_or_ps(_mm_cmple_ps(d, abs_delta), _mm_cmplt_ps(d, _mm_set1_ps(std::numeric_limits<float>::min())));
  // the lens (garbage in lanes that are apart or contained; blended away below)
  const __m128 s = _mm_sub_ps(sum, d);
  const __m128 half_inv_d = _mm_div_ps(_mm_set1_ps(0.5f), d);
  const __m128 p1 = _mm_mul_ps(_mm_sub_ps(d, delta), half_inv_d);
  const __m128 p2 = _mm_mul_ps(_mm_add_ps(d, delta), half_inv_d);
  const __m128 three = _mm_set1_ps(3.f);
  const __m128 t1 = _mm_mul_ps(_mm_mul_ps(p1, p1), _mm_sub_ps(_mm_mul_ps(three, ar), _mm_mul_ps(s, p1)));
  const __m128 t2 = _mm_mul_ps(_mm_mul_ps(p2, p2), _mm_sub_ps(_mm_mul_ps(three, br), _mm_mul_ps(s, p2)));
  const __m128 t12 = _mm_add_ps(t1, t2);
  const __m128 lens = _mm_min_ps(contained, _mm_mul_ps(_mm_mul_ps(_mm_mul_ps(_mm_set1_ps(kPiThirdF), s), s), t12));
  const __m128 lens_area = _mm_mul_ps(_mm_mul_ps(_mm_mul_ps(_mm_mul_ps(_mm_set1_ps(kPiF), s), _mm_add_ps(sum, d)), p1), p2);
  const __m128 lens_offset = _mm_div_ps(_mm_mul_ps(d, t2), t12);
  const __m128 contained_offset = _mm_andnot_ps(_mm_cmple_ps(ar, br), d);  // ar <= br ? 0 : d
  const __m128 volume =
      _mm_and_ps(touching, _mm_or_ps(_mm_and_ps(containment, contained), _mm_andnot_ps(containment, lens)));
  const __m128 area = _mm_and_ps(_mm_andnot_ps(containment, touching), lens_area);
  const __m128 offset = _mm_or_ps(_mm_and_ps(containment, contained_offset), _mm_andnot_ps(containment, lens_offset));
  const __m128 inv = _mm_and_ps(_mm_cmpgt_ps(d, zero), _mm_div_ps(_mm_set1_ps(1.f), d));
  const __m128 nx = _mm_mul_ps(dx, inv), ny = _mm_mul_ps(dy, inv), nz = _mm_mul_ps(dz, inv);
  _mm_store_ps(out.volume, volume);
  _mm_store_ps(out.area, area);
  _mm_store_ps(out.nx, nx);
  _mm_store_ps(out.ny, ny);
  _mm_store_ps(out.nz, nz);
  _mm_store_ps(out.cx, _mm_add_ps(ax, _mm_mul_ps(nx, offset)));
  _mm_store_ps(out.cy, _mm_add_ps(ay, _mm_mul_ps(ny, offset)));
  _mm_store_ps(out.cz, _mm_add_ps(az, _mm_mul_ps(nz, offset)));
  const __m128 overlap = _mm_cmpgt_ps(volume, zero);
  near = margin > 0.f ? static_cast<std::uint32_t>(_mm_movemask_ps(
                            _mm_andnot_ps(overlap, _mm_cmplt_ps(d, _mm_add_ps(sum, _mm_set1_ps(margin))))))
                      : 0u;
  return static_cast<std::uint32_t>(_mm_movemask_ps(overlap));
}
#endif

/// The same for one lane, with the scalar kernel (builds without SSE2).
[[gnu::always_inline]] inline std::uint32_t lens_lane1(const LeafBatch& b, int i, float margin, LensLanes& out,
                                                       std::uint32_t& near) {
  const float dx = b.bx[i] - b.ax[i], dy = b.by[i] - b.ay[i], dz = b.bz[i] - b.az[i];
  const float d = std::sqrt(dx * dx + dy * dy + dz * dz);
  const SphereOverlap<float> o = sphere_overlap(d, b.ar[i], b.br[i]);
  const float inv = d > 0.f ? 1.f / d : 0.f;
  out.volume[0] = o.volume;
  out.area[0] = o.area;
  out.nx[0] = dx * inv;
  out.ny[0] = dy * inv;
  out.nz[0] = dz * inv;
  out.cx[0] = b.ax[i] + out.nx[0] * o.centroid_offset;
  out.cy[0] = b.ay[i] + out.ny[0] * o.centroid_offset;
  out.cz[0] = b.az[i] + out.nz[0] * o.centroid_offset;
  const bool overlap = o.volume > 0.f;
  near = !overlap && margin > 0.f && d < b.ar[i] + b.br[i] + margin ? 1u : 0u;
  return overlap ? 1u : 0u;
}

}  // namespace uh::collette::detail
