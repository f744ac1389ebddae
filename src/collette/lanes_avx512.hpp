#pragma once
// F16: sixteen float lanes for the queries' kernels on AVX-512 (private to Collette).
//
// The same operations as F4 and F8 (lanes_sse2.hpp, lanes_avx2.hpp), sixteen lanes wide, except
// that comparisons give an M16: AVX-512 keeps masks in mask registers, one bit per lane, so a mask
// blends a value with a zeroing move instead of a bitwise and. Every blend selects a lane or zero,
// exactly as and-ing with an all-ones or all-zero lane does, so the lanes are bit for bit those of
// F4 and F8. Include it only inside a region compiled for AVX-512 F, VL, DQ and BW
// (volume_query_avx512.cpp), reached only after the CPU was checked for them.

#include <immintrin.h>
#include <cstdint>

#include "lanes_avx2.hpp"

namespace uh::collette::detail {

/// A mask of sixteen lanes, one bit per lane.
struct M16 {
  __mmask16 k;
};

struct F16 {
  static constexpr int kWidth = 16;
  __m512 v;

  [[gnu::always_inline]] static F16 load(const float* p) { return {_mm512_loadu_ps(p)}; }
  [[gnu::always_inline]] static F16 set1(float x) { return {_mm512_set1_ps(x)}; }
  [[gnu::always_inline]] static F16 zero() { return {_mm512_setzero_ps()}; }
  /// the eight floats at p in lanes 0..7 and again in lanes 8..15
  [[gnu::always_inline]] static F16 load_twice(const float* p) {
    return {_mm512_broadcast_f32x8(_mm256_loadu_ps(p))};
  }
  /// Eight fields of sixteen lanes (field i, lane j at f[i * stride + j]) into sixteen rows of
  /// eight (rows[8 j + i]): F8's transpose on each half.
  [[gnu::always_inline]] static void to_rows(const float* f, int stride, float* rows) {
    F8::to_rows(f, stride, rows);
    F8::to_rows(f + 8, stride, rows + 64);
  }
  /// lane j of the eight lanes v in lanes 0..7, lane j + 1 in lanes 8..15 (one permute)
  [[gnu::always_inline]] static F16 spread_pair(F8 v, int j) {
    const __m512i index = _mm512_mask_mov_epi32(_mm512_set1_epi32(j), 0xff00, _mm512_set1_epi32(j + 1));
    return {_mm512_permutexvar_ps(index, _mm512_castps256_ps512(v.v))};
  }
};

[[gnu::always_inline]] inline void store(float* p, F16 a) { _mm512_storeu_ps(p, a.v); }
[[gnu::always_inline]] inline F16 operator+(F16 a, F16 b) { return {_mm512_add_ps(a.v, b.v)}; }
[[gnu::always_inline]] inline F16 operator-(F16 a, F16 b) { return {_mm512_sub_ps(a.v, b.v)}; }
[[gnu::always_inline]] inline F16 operator*(F16 a, F16 b) { return {_mm512_mul_ps(a.v, b.v)}; }
[[gnu::always_inline]] inline F16 operator/(F16 a, F16 b) { return {_mm512_div_ps(a.v, b.v)}; }
[[gnu::always_inline]] inline F16 sqrt(F16 a) { return {_mm512_sqrt_ps(a.v)}; }
// a < b ? a : b per lane, as SSE's minps (vminps keeps that rule at every width)
[[gnu::always_inline]] inline F16 min(F16 a, F16 b) { return {_mm512_min_ps(a.v, b.v)}; }
// ordered, quiet: the lanes of SSE's cmpltps / cmpleps / cmpgtps
[[gnu::always_inline]] inline M16 operator<(F16 a, F16 b) {
  return {_mm512_cmp_ps_mask(a.v, b.v, _CMP_LT_OQ)};
}
[[gnu::always_inline]] inline M16 operator<=(F16 a, F16 b) {
  return {_mm512_cmp_ps_mask(a.v, b.v, _CMP_LE_OQ)};
}
[[gnu::always_inline]] inline M16 operator>(F16 a, F16 b) {
  return {_mm512_cmp_ps_mask(a.v, b.v, _CMP_GT_OQ)};
}
[[gnu::always_inline]] inline M16 operator&(M16 a, M16 b) { return {static_cast<__mmask16>(a.k & b.k)}; }
[[gnu::always_inline]] inline M16 operator|(M16 a, M16 b) { return {static_cast<__mmask16>(a.k | b.k)}; }
/// ~mask & b
[[gnu::always_inline]] inline M16 andnot(M16 mask, M16 b) { return {static_cast<__mmask16>(~mask.k & b.k)}; }
/// the lanes of b where the mask is set, zero elsewhere
[[gnu::always_inline]] inline F16 operator&(M16 mask, F16 b) { return {_mm512_maskz_mov_ps(mask.k, b.v)}; }
/// zero where the mask is set, the lanes of b elsewhere
[[gnu::always_inline]] inline F16 andnot(M16 mask, F16 b) {
  return {_mm512_maskz_mov_ps(static_cast<__mmask16>(~mask.k), b.v)};
}
[[gnu::always_inline]] inline F16 operator|(F16 a, F16 b) { return {_mm512_or_ps(a.v, b.v)}; }
[[gnu::always_inline]] inline F16 abs(F16 a) { return {_mm512_abs_ps(a.v)}; }
/// bit j set when lane j of the mask is set
[[gnu::always_inline]] inline std::uint32_t bits(M16 mask) { return static_cast<std::uint32_t>(mask.k); }

}  // namespace uh::collette::detail
