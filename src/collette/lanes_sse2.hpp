#pragma once
// F4: four float lanes for the queries' kernels on the baseline ISA (private to Collette).
//
// The kernels (volume_fast_path.inl) are written once against a lane type and compiled for each
// instruction set: F4 here (SSE2, part of every x86-64; a plain four-float loop elsewhere) and F8
// (lanes_avx2.hpp, AVX2 behind a runtime check). Every operation is one IEEE operation per lane,
// correctly rounded, so a lane computes exactly what the scalar code computes with the same
// operations in the same order, whatever the width. min() is SSE's: `a < b ? a : b` per lane, which
// is std::min(b, a). Masks are all-ones or all-zero lanes.

#include <cstdint>

#if defined(__SSE2__)
#include <immintrin.h>
#else
#include <bit>
#include <cmath>
#endif

namespace uh::collette::detail {

#if defined(__SSE2__)

struct F4 {
  static constexpr int kWidth = 4;
  __m128 v;

  [[gnu::always_inline]] static F4 load(const float* p) { return {_mm_loadu_ps(p)}; }
  [[gnu::always_inline]] static F4 set1(float x) { return {_mm_set1_ps(x)}; }
  [[gnu::always_inline]] static F4 zero() { return {_mm_setzero_ps()}; }
  /// Eight fields of four lanes (field i, lane j at f[i * stride + j]) into four rows of eight
  /// (rows[8 j + i]): two 4 x 4 transposes.
  [[gnu::always_inline]] static void to_rows(const float* f, int stride, float* rows) {
    for (int h = 0; h < 8; h += 4) {
      __m128 r0 = _mm_loadu_ps(f + h * stride), r1 = _mm_loadu_ps(f + (h + 1) * stride);
      __m128 r2 = _mm_loadu_ps(f + (h + 2) * stride), r3 = _mm_loadu_ps(f + (h + 3) * stride);
      _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
      _mm_storeu_ps(rows + h, r0);
      _mm_storeu_ps(rows + 8 + h, r1);
      _mm_storeu_ps(rows + 16 + h, r2);
      _mm_storeu_ps(rows + 24 + h, r3);
    }
  }
};

[[gnu::always_inline]] inline void store(float* p, F4 a) { _mm_storeu_ps(p, a.v); }
[[gnu::always_inline]] inline F4 operator+(F4 a, F4 b) { return {_mm_add_ps(a.v, b.v)}; }
[[gnu::always_inline]] inline F4 operator-(F4 a, F4 b) { return {_mm_sub_ps(a.v, b.v)}; }
[[gnu::always_inline]] inline F4 operator*(F4 a, F4 b) { return {_mm_mul_ps(a.v, b.v)}; }
[[gnu::always_inline]] inline F4 operator/(F4 a, F4 b) { return {_mm_div_ps(a.v, b.v)}; }
[[gnu::always_inline]] inline F4 sqrt(F4 a) { return {_mm_sqrt_ps(a.v)}; }
[[gnu::always_inline]] inline F4 min(F4 a, F4 b) { return {_mm_min_ps(a.v, b.v)}; }
[[gnu::always_inline]] inline F4 operator<(F4 a, F4 b) { return {_mm_cmplt_ps(a.v, b.v)}; }
[[gnu::always_inline]] inline F4 operator<=(F4 a, F4 b) { return {_mm_cmple_ps(a.v, b.v)}; }
[[gnu::always_inline]] inline F4 operator>(F4 a, F4 b) { return {_mm_cmpgt_ps(a.v, b.v)}; }
[[gnu::always_inline]] inline F4 operator&(F4 a, F4 b) { return {_mm_and_ps(a.v, b.v)}; }
[[gnu::always_inline]] inline F4 operator|(F4 a, F4 b) { return {_mm_or_ps(a.v, b.v)}; }
/// ~mask & b
[[gnu::always_inline]] inline F4 andnot(F4 mask, F4 b) { return {_mm_andnot_ps(mask.v, b.v)}; }
[[gnu::always_inline]] inline F4 abs(F4 a) { return {_mm_andnot_ps(_mm_set1_ps(-0.f), a.v)}; }
/// bit j set when lane j of the mask is set
[[gnu::always_inline]] inline std::uint32_t bits(F4 mask) {
  return static_cast<std::uint32_t>(_mm_movemask_ps(mask.v));
}
/// prefetch a cache line into L1
[[gnu::always_inline]] inline void prefetch(const void* p) {
  _mm_prefetch(static_cast<const char*>(p), _MM_HINT_T0);
}

#else

// without SSE2: the same operations one lane at a time
struct F4 {
  static constexpr int kWidth = 4;
  float v[4];

  static F4 load(const float* p) { return {{p[0], p[1], p[2], p[3]}}; }
  static F4 set1(float x) { return {{x, x, x, x}}; }
  static F4 zero() { return set1(0.f); }
  static void to_rows(const float* f, int stride, float* rows) {
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 8; ++i) rows[8 * j + i] = f[i * stride + j];
  }
};

template <typename Op>
inline F4 lanewise(F4 a, F4 b, Op op) {
  F4 r;
  for (int i = 0; i < 4; ++i) r.v[i] = op(a.v[i], b.v[i]);
  return r;
}
inline float mask_of(bool b) { return std::bit_cast<float>(b ? ~0u : 0u); }
template <typename Op>
inline F4 bitwise(F4 a, F4 b, Op op) {
  return lanewise(a, b, [op](float x, float y) {
    return std::bit_cast<float>(op(std::bit_cast<std::uint32_t>(x), std::bit_cast<std::uint32_t>(y)));
  });
}

inline void store(float* p, F4 a) {
  for (int i = 0; i < 4; ++i) p[i] = a.v[i];
}
inline F4 operator+(F4 a, F4 b) {
  return lanewise(a, b, [](float x, float y) { return x + y; });
}
inline F4 operator-(F4 a, F4 b) {
  return lanewise(a, b, [](float x, float y) { return x - y; });
}
inline F4 operator*(F4 a, F4 b) {
  return lanewise(a, b, [](float x, float y) { return x * y; });
}
inline F4 operator/(F4 a, F4 b) {
  return lanewise(a, b, [](float x, float y) { return x / y; });
}
inline F4 sqrt(F4 a) {
  return lanewise(a, a, [](float x, float) { return std::sqrt(x); });
}
inline F4 min(F4 a, F4 b) {
  return lanewise(a, b, [](float x, float y) { return x < y ? x : y; });
}
inline F4 operator<(F4 a, F4 b) {
  return lanewise(a, b, [](float x, float y) { return mask_of(x < y); });
}
inline F4 operator<=(F4 a, F4 b) {
  return lanewise(a, b, [](float x, float y) { return mask_of(x <= y); });
}
inline F4 operator>(F4 a, F4 b) {
  return lanewise(a, b, [](float x, float y) { return mask_of(x > y); });
}
inline F4 operator&(F4 a, F4 b) {
  return bitwise(a, b, [](std::uint32_t x, std::uint32_t y) { return x & y; });
}
inline F4 operator|(F4 a, F4 b) {
  return bitwise(a, b, [](std::uint32_t x, std::uint32_t y) { return x | y; });
}
inline F4 andnot(F4 mask, F4 b) {
  return bitwise(mask, b, [](std::uint32_t x, std::uint32_t y) { return ~x & y; });
}
inline F4 abs(F4 a) {
  return lanewise(a, a, [](float x, float) { return std::fabs(x); });
}
inline std::uint32_t bits(F4 mask) {
  std::uint32_t r = 0;
  for (int i = 0; i < 4; ++i) r |= (std::bit_cast<std::uint32_t>(mask.v[i]) >> 31) << i;
  return r;
}
inline void prefetch(const void*) {}

#endif

}  // namespace uh::collette::detail
