#pragma once
// F8: eight float lanes for the queries' kernels on AVX2 (private to Collette).
//
// The same operations as F4 (lanes_sse2.hpp), eight lanes wide. Include it only inside a region
// compiled for AVX2 (volume_query_avx2.cpp), reached only after the CPU was checked for it. The
// region enables AVX2 but not FMA, so the compiler cannot contract a * b + c into one rounding:
// each lane stays bit for bit the scalar result.

#include <immintrin.h>
#include <cstdint>

namespace uh::collette::detail {

struct F8 {
  static constexpr int kWidth = 8;
  __m256 v;

  [[gnu::always_inline]] static F8 load(const float* p) { return {_mm256_loadu_ps(p)}; }
  [[gnu::always_inline]] static F8 set1(float x) { return {_mm256_set1_ps(x)}; }
  [[gnu::always_inline]] static F8 zero() { return {_mm256_setzero_ps()}; }
  /// the four floats at p in lanes 0..3 and again in lanes 4..7
  [[gnu::always_inline]] static F8 load_twice(const float* p) {
    return {_mm256_broadcast_ps(reinterpret_cast<const __m128*>(p))};
  }
  /// lane j of v in lanes 0..3, lane j + 1 in lanes 4..7
  [[gnu::always_inline]] static F8 spread_pair(F8 v, int j) {
    return {_mm256_permutevar8x32_ps(v.v, _mm256_setr_epi32(j, j, j, j, j + 1, j + 1, j + 1, j + 1))};
  }
  /// Eight fields of eight lanes (field i, lane j at f[i * stride + j]) into eight rows of eight
  /// (rows[8 j + i]): an 8 x 8 transpose.
  [[gnu::always_inline]] static void to_rows(const float* f, int stride, float* rows) {
    __m256 r[8], t[8];
    for (int i = 0; i < 8; ++i) r[i] = _mm256_loadu_ps(f + i * stride);
    for (int i = 0; i < 8; i += 2) {
      t[i] = _mm256_unpacklo_ps(r[i], r[i + 1]);
      t[i + 1] = _mm256_unpackhi_ps(r[i], r[i + 1]);
    }
    for (int i = 0; i < 8; i += 4) {
      r[i] = _mm256_shuffle_ps(t[i], t[i + 2], 0x44);
      r[i + 1] = _mm256_shuffle_ps(t[i], t[i + 2], 0xee);
      r[i + 2] = _mm256_shuffle_ps(t[i + 1], t[i + 3], 0x44);
      r[i + 3] = _mm256_shuffle_ps(t[i + 1], t[i + 3], 0xee);
    }
    for (int i = 0; i < 4; ++i) {
      _mm256_storeu_ps(rows + 8 * i, _mm256_permute2f128_ps(r[i], r[i + 4], 0x20));
      _mm256_storeu_ps(rows + 8 * (i + 4), _mm256_permute2f128_ps(r[i], r[i + 4], 0x31));
    }
  }
};

[[gnu::always_inline]] inline void store(float* p, F8 a) { _mm256_storeu_ps(p, a.v); }
[[gnu::always_inline]] inline F8 operator+(F8 a, F8 b) { return {_mm256_add_ps(a.v, b.v)}; }
[[gnu::always_inline]] inline F8 operator-(F8 a, F8 b) { return {_mm256_sub_ps(a.v, b.v)}; }
[[gnu::always_inline]] inline F8 operator*(F8 a, F8 b) { return {_mm256_mul_ps(a.v, b.v)}; }
[[gnu::always_inline]] inline F8 operator/(F8 a, F8 b) { return {_mm256_div_ps(a.v, b.v)}; }
[[gnu::always_inline]] inline F8 sqrt(F8 a) { return {_mm256_sqrt_ps(a.v)}; }
[[gnu::always_inline]] inline F8 min(F8 a, F8 b) { return {_mm256_min_ps(a.v, b.v)}; }
// ordered, quiet: the same lanes as SSE's cmpltps / cmpleps (which differ only in raising the
// invalid flag on NaN, and the kernels read no flags)
[[gnu::always_inline]] inline F8 operator<(F8 a, F8 b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_LT_OQ)}; }
[[gnu::always_inline]] inline F8 operator<=(F8 a, F8 b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_LE_OQ)}; }
[[gnu::always_inline]] inline F8 operator>(F8 a, F8 b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_GT_OQ)}; }
[[gnu::always_inline]] inline F8 operator&(F8 a, F8 b) { return {_mm256_and_ps(a.v, b.v)}; }
[[gnu::always_inline]] inline F8 operator|(F8 a, F8 b) { return {_mm256_or_ps(a.v, b.v)}; }
/// ~mask & b
[[gnu::always_inline]] inline F8 andnot(F8 mask, F8 b) { return {_mm256_andnot_ps(mask.v, b.v)}; }
[[gnu::always_inline]] inline F8 abs(F8 a) { return {_mm256_andnot_ps(_mm256_set1_ps(-0.f), a.v)}; }
/// bit j set when lane j of the mask is set
[[gnu::always_inline]] inline std::uint32_t bits(F8 mask) {
  return static_cast<std::uint32_t>(_mm256_movemask_ps(mask.v));
}

}  // namespace uh::collette::detail
