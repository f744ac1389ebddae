// The volume query's fast path compiled for AVX2 (eight lanes), chosen at run time.
//
// The build targets baseline x86-64, so only the functions defined between the target pragmas
// below use AVX2 instructions, and VolumeQuery calls them only after supported() said yes: the
// library still runs on any x86-64. The region enables AVX2 but not FMA: a fused a * b + c rounds
// once, the scalar kernel twice, and the lanes must stay bit for bit the scalar result. Every header is
// included before the region, so inline functions they define (the standard library's included) stay baseline
// code, which avoids two different definitions of one inline function.
//
// Windows builds leave the AVX2 path out: MinGW's gcc cannot align the stack to 32 bytes when it
// spills AVX registers (gcc bug 54412), so the baseline kernels run there.

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>

#include "lanes_sse2.hpp"
#include "volume_traversal.hpp"

#if defined(__x86_64__) && !defined(_WIN32) && (defined(__GNUC__) || defined(__clang__))
#define UH_COLLETTE_AVX2 1
#include <immintrin.h>
#endif

#if defined(UH_COLLETTE_AVX2)

namespace uh::collette::detail::avx2 {

bool supported() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2");
}

}  // namespace uh::collette::detail::avx2

#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx2"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2")
#endif

#include "lanes_avx2.hpp"

namespace uh::collette::detail::avx2 {
using V = F8;
// a block of 4 children: one group of four lanes
template <int W>
using BlockLanes = std::conditional_t<(W < 8), F4, F8>;
#include "volume_fast_path.inl"
}  // namespace uh::collette::detail::avx2

#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif

#else

namespace uh::collette::detail::avx2 {
bool supported() { return false; }
// never called (supported() is false); the baseline path, should it be
void run_fast(Traversal& t) { sse2::run_fast(t); }
void expand(Traversal& t, std::size_t entries) { sse2::expand(t, entries); }
}  // namespace uh::collette::detail::avx2

#endif
