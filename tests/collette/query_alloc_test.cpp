// Replaces the global allocation functions for the whole test program to count allocations made
// by this thread; the counting is only read by the test below.

#include <gtest/gtest.h>

#include <cstdlib>
#include <new>

#include "tree_test_support.hpp"
#include "uh/collette/distance_query.hpp"
#include "uh/collette/sphere_tree_builder.hpp"
#include "uh/collette/time_critical_query.hpp"
#include "uh/collette/volume_query.hpp"

namespace {
thread_local long g_allocations = 0;
}  // namespace

#if defined(__SANITIZE_ADDRESS__)
// Shared libraries keep using AddressSanitizer's operator new while their deletes may reach the
// replacement below (or the other way round): both end in malloc/free, so the pairing is sound.
extern "C" const char* __asan_default_options() { return "alloc_dealloc_mismatch=0"; }
#endif

// gcc flags free() inside a replacement operator delete as mismatched; here it is the point
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif
void* operator new(std::size_t n) {
  ++g_allocations;
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) {
  ++g_allocations;
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

namespace uh::collette {
namespace {

TEST(VolumeQuery, SteadyStateDoesNotAllocate) {
  const auto ta = build_sphere_tree(testing::make_packing(0.07, testing::Shape::kBall, 81));
  const auto tb = build_sphere_tree(testing::make_packing(0.08, testing::Shape::kBox, 82));
  ASSERT_TRUE(ta && tb);
  VolumeQuery vq;
  VolumeQuery coherent({.coherence_skin = 0.05f});  // traverses on each jump, reuses on each repeat
  TimeCriticalQuery tc;
  DistanceQuery dq;
  core::SplitMix64 rng{1};
  std::vector<Pose> poses;
  for (int k = 0; k < 30; ++k) poses.push_back(testing::random_pose(rng, 1.0));
  poses.push_back(Pose{{}, {5.0, 0.0, 0.0}});
  // warm-up: every scratch buffer reaches its high-water mark
  for (const Pose& p : poses) {
    (void)vq.run(*ta, *tb, p);
    (void)coherent.run(*ta, *tb, p);
    (void)coherent.run(*ta, *tb, p);
    (void)tc.run(*ta, *tb, p);
    (void)dq.run(*ta, *tb, p);
  }
  const long before = g_allocations;
  double volume = 0.0;
  std::int64_t pairs = 0;
  int reused = 0;
  for (const Pose& p : poses) {
    volume += vq.run(*ta, *tb, p).total_volume;
    volume += coherent.run(*ta, *tb, p).total_volume;
    reused += coherent.run(*ta, *tb, p).reused_candidates ? 1 : 0;
    pairs += vq.result().stats.overlapping_pairs;
    volume += tc.run(*ta, *tb, p, {.max_expansions = 200}).volume_estimate;
    volume += dq.run(*ta, *tb, p).distance;
  }
  EXPECT_EQ(g_allocations - before, 0);
  EXPECT_EQ(reused, static_cast<int>(poses.size()));
  EXPECT_GT(pairs, 1000) << "the poses must exercise the traversal";
  EXPECT_GT(volume, 0.0);
  // the counter itself works
  const long probe = g_allocations;
  auto* leak_check = new int(3);
  EXPECT_EQ(g_allocations - probe, 1);
  delete leak_check;
}

}  // namespace
}  // namespace uh::collette
