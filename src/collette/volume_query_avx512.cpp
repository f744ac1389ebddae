// The volume query's fast path compiled for AVX-512 (sixteen lanes), chosen at run time.
//
// As volume_query_avx2.cpp: the build targets baseline x86-64, only the functions defined between
// the target pragmas below use AVX-512 instructions, and VolumeQuery calls them only after
// supported() said yes, so the library still runs on any x86-64. Compiling the whole file with
// -mavx512f would not do: inline functions of the headers (the standard library's) would be compiled
// for AVX-512 here too, and the linker may keep that copy for every file. The lens kernel runs 16
// leaf pairs per call; an inner visit tests two rows of its 8 x 8 child pairs per group (A's eight
// children twice, against two children of B), so four groups instead of eight; masks stay in mask
// registers. AVX-512F includes fused multiply-adds, which round once where the scalar kernel rounds
// twice: this file is compiled with -ffp-contract=off (src/collette/tree_sources.cmake), so the
// compiler never fuses and every lane stays bit for bit the scalar result.
//
// Windows builds leave it out, as the AVX2 path (gcc bug 54412: MinGW cannot align the stack for
// spilled vector registers).

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>

#include "lanes_sse2.hpp"
#include "volume_traversal.hpp"

#if defined(__x86_64__) && !defined(_WIN32) && (defined(__GNUC__) || defined(__clang__))
#define UH_COLLETTE_AVX512 1
#include <immintrin.h>
#endif

#if defined(UH_COLLETTE_AVX512)

namespace uh::collette::detail::avx512 {

bool supported() {
  __builtin_cpu_init();
  // libgcc's check includes the operating system's support for the 512-bit register state (XCR0)
  return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
         __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512bw");
}

// AMD's Zen 4 runs a 512-bit operation as two 256-bit halves at full clock: there the 16-lane
// kernels measured 0.87-0.89 of the 8-lane ones' median. Intel's AVX-512 cores lower the clock while
// they run 512-bit arithmetic (also for the few 512-bit double sums that the compiler vectorises in
// this file's lens loop): on a Xeon of family 6 model 167 the 8-lane kernels measured 0.90-0.93 of
// the 16-lane ones' median (docs/benchmarks.md), as compilers too prefer 256-bit vectors there.
bool preferred() {
  __builtin_cpu_init();
  return __builtin_cpu_is("amd");
}

}  // namespace uh::collette::detail::avx512

#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx2,avx512f,avx512vl,avx512dq,avx512bw"))), \
                             apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2,avx512f,avx512vl,avx512dq,avx512bw")
#endif

#include "lanes_avx2.hpp"
#include "lanes_avx512.hpp"

namespace uh::collette::detail::avx512 {
using V = F16;
// blocks are at most 8 children: eight lanes (or four) per node test
template <int W>
using BlockLanes = std::conditional_t<(W < 8), F4, F8>;
#include "volume_fast_path.inl"
}  // namespace uh::collette::detail::avx512

#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif

#else

namespace uh::collette::detail::avx512 {
bool supported() { return false; }
bool preferred() { return false; }
// never called (supported() is false); the baseline path, should it be
void run_fast(Traversal& t) { sse2::run_fast(t); }
void expand(Traversal& t, std::size_t entries) { sse2::expand(t, entries); }
}  // namespace uh::collette::detail::avx512

#endif
