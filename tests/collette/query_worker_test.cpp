// VolumeQuery with its worker thread (VolumeQueryOptions::worker_thread): the same pairs, bytes and
// totals as one thread. Labelled "threads" (this executable), so it also runs under ThreadSanitizer.

#include <gtest/gtest.h>

#include <cstring>
#include <utility>
#include <vector>

#include "tree_test_support.hpp"
#include "uh/collette/sphere_tree_builder.hpp"
#include "uh/collette/volume_query.hpp"

namespace uh::collette {
namespace {

using testing::make_packing;
using testing::Shape;

// One pose against one thread: every stored pair byte for byte in the same order, the same counts,
// and totals summed in the same order (equal, not close).
void expect_same_as_one_thread(VolumeQuery& shared, VolumeQuery& single, const SphereTree& ta,
                               const SphereTree& tb, const Pose& pose) {
  const VolumeQueryResult s = shared.run(ta, tb, pose);
  const VolumeQueryResult& r = single.run(ta, tb, pose);
  ASSERT_EQ(s.pair_count, r.pair_count);
  ASSERT_EQ(s.stats.overlapping_pairs, r.stats.overlapping_pairs);
  ASSERT_EQ(s.stats.node_pairs_visited, r.stats.node_pairs_visited);
  ASSERT_EQ(s.stats.leaf_pairs_tested, r.stats.leaf_pairs_tested);
  ASSERT_EQ(s.near_pairs, r.near_pairs);
  ASSERT_EQ(s.truncated, r.truncated);
  ASSERT_EQ(std::memcmp(shared.pairs().data(), single.pairs().data(), single.pairs().size_bytes()), 0);
  testing::expect_identical_totals(s, r);
}

TEST(VolumeQueryWorker, SameResultsAsOneThreadOnDeepPoses) {
  const auto la = make_packing(0.11, Shape::kBall, 91);
  const auto lb = make_packing(0.09, Shape::kBox, 92);
  for (const auto& [arity_a, arity_b] : {std::pair{8, 8}, std::pair{4, 8}}) {
    const auto ta = build_sphere_tree(la, {.arity = arity_a});
    const auto tb = build_sphere_tree(lb, {.arity = arity_b});
    ASSERT_TRUE(ta && tb);
    const auto poses =
        testing::deep_poses(*ta, *tb, 4, 500u + static_cast<std::uint32_t>(arity_a * 10 + arity_b));
    for (const float margin : {0.f, 0.02f}) {
      for (const testing::KernelChoice& kernels : testing::kKernelChoices) {
        SCOPED_TRACE(kernels.name);
        const bool avx2 = kernels.use_avx2, avx512 = kernels.use_avx512, force = kernels.force_avx512;
        // the worker claims first, so that its part (and the merge) runs in every run
        VolumeQuery shared({.contact_margin = margin,
                            .use_avx2 = avx2,
                            .use_avx512 = avx512,
                            .force_avx512 = force,
                            .worker_thread = true,
                            .worker_claims_first = true});
        VolumeQuery single(
            {.contact_margin = margin, .use_avx2 = avx2, .use_avx512 = avx512, .force_avx512 = force});
        int worker_chunks = 0;
        for (const Pose& pose : poses) {
          expect_same_as_one_thread(shared, single, *ta, *tb, pose);
          worker_chunks += shared.worker_chunks();
        }
        EXPECT_GE(worker_chunks, static_cast<int>(poses.size()))
            << "the worker ran no chunk: the test would prove little";
        EXPECT_GT(single.result().pair_count, 150);
        // and a run where the caller may take every chunk (whatever the worker manages)
        VolumeQuery racing(
            {.contact_margin = margin,
             .use_avx2 = avx2,
             .use_avx512 = avx512,
             .force_avx512 = force,
             .worker_thread = true});
        for (int repeat = 0; repeat < 3; ++repeat)
          for (const Pose& pose : poses) expect_same_as_one_thread(racing, single, *ta, *tb, pose);
      }
    }
  }
}

TEST(VolumeQueryWorker, WorkerBufferOverflowFallsBackToTheCaller) {
  // more pairs than the worker's buffer holds: the caller runs the worker's chunks itself, and
  // the results still match one thread (the totals cover every pair; pairs stop at the capacity)
  const auto la = make_packing(0.1, Shape::kBall, 93);
  const auto ta = build_sphere_tree(la);
  ASSERT_TRUE(ta);
  const auto poses = testing::deep_poses(*ta, *ta, 2, 600u);
  VolumeQuery single({.pair_capacity = 100});
  VolumeQuery shared({.pair_capacity = 100, .worker_thread = true, .worker_claims_first = true});
  for (const Pose& pose : poses) {
    expect_same_as_one_thread(shared, single, *ta, *ta, pose);
    EXPECT_TRUE(single.result().truncated);
    EXPECT_GT(single.result().stats.overlapping_pairs, 1000) << "the worker's buffer did not overflow";
    EXPECT_EQ(shared.worker_chunks(), 0) << "the worker's pairs were added from an overflowing buffer";
  }
}

TEST(VolumeQueryWorker, StartsAndStopsWithTheQuery) {
  // construction starts the thread and destruction joins it, also after a move and without runs
  const auto la = make_packing(0.2, Shape::kBall, 94);
  const auto ta = build_sphere_tree(la);
  ASSERT_TRUE(ta);
  { VolumeQuery idle({.worker_thread = true}); }
  VolumeQuery a({.worker_thread = true});
  VolumeQuery b = std::move(a);
  VolumeQuery single;
  expect_same_as_one_thread(b, single, *ta, *ta, Pose{});
  EXPECT_GT(single.result().pair_count, 0);
}

}  // namespace
}  // namespace uh::collette
