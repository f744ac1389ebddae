#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iterator>
#include <limits>
#include <memory>
#include <random>
#include <set>
#include <tuple>
#include <utility>
#include <vector>

#include "tree_test_support.hpp"
#include "uh/collette/sphere_tree_builder.hpp"
#include "uh/collette/volume_query.hpp"
#include "uh/core/sphere_overlap.hpp"

namespace uh::collette {
namespace {

using testing::brute_volume;
using testing::make_packing;
using testing::Shape;

Vec3 v3(const float f[3]) { return {static_cast<double>(f[0]), static_cast<double>(f[1]), static_cast<double>(f[2])}; }

// The query's result at one pose against brute force over all leaf pairs (long double lens
// reference, double sums). Returns false (after failing) when the pose's check failed.
void expect_pose_matches_brute_force(VolumeQuery& query, const SphereTree& ta, const SphereTree& tb,
                                     const std::vector<Sphere>& la, const std::vector<Sphere>& lb,
                                     const Pose& pose, int k) {
  const VolumeQueryResult& r = query.run(ta, tb, pose);
  const testing::BruteVolume ref = brute_volume(la, lb, pose);
  const double scale = std::max(ref.volume, 1e-9);
  ASSERT_NEAR(r.total_volume, ref.volume, 1e-4 * scale + 1e-9) << "pose " << k;
  ASSERT_EQ(r.stats.overlapping_pairs, r.pair_count);
  if (ref.volume == 0.0) {
    EXPECT_EQ(r.pair_count, 0);
    return;
  }
  // the same pair set, up to pairs whose lens is at float round-off
  std::set<std::pair<int, int>> got;
  for (const PairOverlap& p : query.pairs()) got.emplace(p.leaf_a, p.leaf_b);
  std::size_t missing = 0;
  for (std::size_t i = 0; i < ref.pairs.size(); ++i)
    if (!got.count(ref.pairs[i])) {
      ++missing;
      EXPECT_LT(ref.pair_volumes[i], 1e-6 * scale) << "pose " << k << " pair missing";
    }
  EXPECT_EQ(got.size(), query.pairs().size()) << "a pair reported twice";
  EXPECT_LE(got.size(), ref.pairs.size() - missing + 2);
  // weighted normal sum and centroid
  const Vec3 dn = r.weighted_normal_sum - ref.normal_sum;
  EXPECT_LT(norm(dn), 1e-4 * scale + 1e-4 * norm(ref.normal_sum)) << "pose " << k;
  EXPECT_LT(norm(r.volume_centroid - ref.centroid_sum / ref.volume), 1e-4) << "pose " << k;
  EXPECT_LT(norm(r.volume_gradient - ref.gradient), 1e-3 * norm(ref.gradient) + 1e-6) << "pose " << k;
  // per-pair entries agree with the totals
  double sum = 0.0;
  Vec3 nsum{};
  for (const PairOverlap& p : query.pairs()) {
    sum += static_cast<double>(p.volume);
    nsum += static_cast<double>(p.volume) * v3(p.normal);
    EXPECT_NEAR(norm(v3(p.normal)), 1.0, 1e-5);
  }
  EXPECT_NEAR(sum, r.total_volume, 1e-5 * r.total_volume);
  EXPECT_LT(norm(nsum - r.weighted_normal_sum), 1e-5 * r.total_volume);
}

void expect_matches_brute_force(const std::vector<Sphere>& la, const std::vector<Sphere>& lb, int arity_a, int arity_b,
                                int poses, std::uint32_t seed) {
  const auto ta = build_sphere_tree(la, {.arity = arity_a});
  const auto tb = build_sphere_tree(lb, {.arity = arity_b});
  ASSERT_TRUE(ta && tb);
  VolumeQuery query;
  core::SplitMix64 rng{seed};
  int overlapping_poses = 0;
  for (int k = 0; k < poses; ++k) {
    const Pose pose = testing::random_pose(rng, 1.2);
    expect_pose_matches_brute_force(query, *ta, *tb, la, lb, pose, k);
    if (query.result().total_volume > 0.0) ++overlapping_poses;
  }
  EXPECT_GT(overlapping_poses, poses / 3) << "the random poses hardly overlap: the test would prove little";
}

TEST(VolumeQuery, MatchesBruteForceOnRandomPoses) {
  const auto ball = make_packing(0.16, Shape::kBall, 21);
  const auto box = make_packing(0.14, Shape::kBox, 22);
  for (int arity : {2, 4, 8}) expect_matches_brute_force(ball, box, arity, arity, 40, 100u + static_cast<std::uint32_t>(arity));
  // trees of different block widths (4 and 8 lanes) against each other
  expect_matches_brute_force(ball, box, 3, 8, 30, 200u);
  expect_matches_brute_force(ball, box, 6, 4, 30, 201u);
}

TEST(VolumeQuery, MatchesBruteForceForSameObject) {
  // an object against a copy of itself: nearly coincident leaves and containment cases
  const auto rod = make_packing(0.07, Shape::kRod, 23);
  expect_matches_brute_force(rod, rod, 4, 4, 30, 7);
  const auto ta = build_sphere_tree(rod);
  ASSERT_TRUE(ta);
  VolumeQuery q;
  const auto& r = q.run(*ta, *ta, Pose{});
  EXPECT_NEAR(r.total_volume, ta->total_volume(), 1e-5 * ta->total_volume());
}

TEST(VolumeQuery, DisjointAndSingleLeafTrees) {
  const std::vector<Sphere> one{{0.f, 0.f, 0.f, 1.f}};
  const auto t = build_sphere_tree(one);
  ASSERT_TRUE(t);
  VolumeQuery q;
  EXPECT_EQ(q.run(*t, *t, Pose{{}, {2.5, 0, 0}}).total_volume, 0.0);
  const auto& r = q.run(*t, *t, Pose{{}, {1.0, 0, 0}});
  EXPECT_NEAR(r.total_volume, 5.0 * kPi / 12.0, 1e-6);  // two unit balls 1 apart: 2 caps of height 1/2
  EXPECT_NEAR(r.restoring_direction.x, 1.0, 1e-9);
  EXPECT_NEAR(r.volume_centroid.x, 0.5, 1e-6);
  ASSERT_EQ(r.pair_count, 1);
}

TEST(VolumeQuery, ContactFrameMatchesResultInWorldFrame) {
  const auto la = make_packing(0.15, Shape::kBall, 31);
  const auto ta = build_sphere_tree(la);
  ASSERT_TRUE(ta);
  const Pose world_from_a{quat_from_axis_angle({0, 0, 1}, 0.7), {1.0, 2.0, 3.0}};
  const Pose b_in_a{quat_from_axis_angle({0, 1, 0}, 0.5), {0.8, 0.1, 0.0}};
  const Pose world_from_b = world_from_a * b_in_a;
  VolumeQuery q;
  const VolumeQueryResult local = q.run(*ta, *ta, b_in_a);
  ASSERT_GT(local.pair_count, 10);
  auto frame = std::make_unique<ContactFrame>();
  q.run(*ta, *ta, world_from_a, world_from_b, *frame);
  EXPECT_NEAR(frame->total_volume, local.total_volume, 1e-6 * local.total_volume);
  EXPECT_EQ(frame->pair_count, local.pair_count);
  EXPECT_FALSE(frame->truncated);
  const Vec3 dir = transform_vector(world_from_a, local.restoring_direction);
  EXPECT_LT(norm(frame->restoring_direction_world - dir), 1e-4);
  EXPECT_LT(norm(frame->volume_centroid_world - transform_point(world_from_a, local.volume_centroid)), 1e-4);
  double sum = 0.0;
  for (int i = 0; i < frame->pair_count; ++i) {
    const SpherePairContact& c = frame->pairs()[static_cast<std::size_t>(i)];
    sum += static_cast<double>(c.volume);
    // recompute the pair from the local spheres and the world poses
    const Vec3 ca = transform_point(world_from_a, testing::centre(c.sphere_a_local));
    const Vec3 cb = transform_point(world_from_b, testing::centre(c.sphere_b_local));
    const double d = norm(cb - ca);
    const uh::test::LensReference lens = uh::test::lens_reference(
        d, static_cast<double>(c.sphere_a_local.radius), static_cast<double>(c.sphere_b_local.radius));
    EXPECT_NEAR(static_cast<double>(c.volume), lens.volume, 1e-4 * static_cast<double>(c.volume) + 1e-7);
    EXPECT_NEAR(static_cast<double>(c.area), lens.area, 1e-4 * lens.area + 1e-6);
    EXPECT_LT(norm(v3(c.normal_world) - normalized(cb - ca)), 1e-3);
    EXPECT_EQ(c.sphere_a_local.x, la[static_cast<std::size_t>(c.leaf_a)].x);
  }
  EXPECT_NEAR(sum, frame->total_volume, 1e-5 * sum);
}

TEST(VolumeQuery, TruncatesAtCapacityButKeepsTotals) {
  const auto la = make_packing(0.15, Shape::kBall, 41);
  const auto ta = build_sphere_tree(la);
  ASSERT_TRUE(ta);
  const Pose pose{quat_from_axis_angle({0, 1, 0}, 0.3), {0.5, 0, 0}};
  VolumeQuery full;
  const VolumeQueryResult all = full.run(*ta, *ta, pose);
  ASSERT_GT(all.pair_count, 20);
  VolumeQuery small({.pair_capacity = 10});
  const VolumeQueryResult& r = small.run(*ta, *ta, pose);
  EXPECT_TRUE(r.truncated);
  EXPECT_EQ(r.pair_count, 10);
  EXPECT_EQ(r.stats.overlapping_pairs, all.stats.overlapping_pairs);
  EXPECT_DOUBLE_EQ(r.total_volume, all.total_volume);
  VolumeQuery none({.collect_pairs = false});
  const VolumeQueryResult& n = none.run(*ta, *ta, pose);
  EXPECT_EQ(n.pair_count, 0);
  EXPECT_FALSE(n.truncated);
  EXPECT_DOUBLE_EQ(n.total_volume, all.total_volume);
}

TEST(VolumeQuery, DeepPosesMatchBruteForce) {
  // a quarter of the volume overlapping: thousands of pairs, every visit type of the traversal;
  // with the AVX2 kernels where the CPU has them, and with the baseline kernels
  const auto la = make_packing(0.13, Shape::kBall, 71);
  const auto lb = make_packing(0.11, Shape::kBox, 72);
  // balanced trees (leaves at one depth), and k-means trees, whose leaves at several depths bring
  // leaf-against-inner visits
  for (const auto& [arity_a, arity_b, split] :
       {std::tuple{8, 8, SphereTreeSplit::kBalanced}, std::tuple{4, 8, SphereTreeSplit::kBalanced},
        std::tuple{8, 3, SphereTreeSplit::kBalanced}, std::tuple{8, 8, SphereTreeSplit::kKMeans},
        std::tuple{8, 3, SphereTreeSplit::kKMeans}}) {
    const auto ta = build_sphere_tree(la, {.arity = arity_a, .split = split});
    const auto tb = build_sphere_tree(lb, {.arity = arity_b, .split = split});
    ASSERT_TRUE(ta && tb);
    const std::vector<Pose> poses = testing::deep_poses(
        *ta, *tb, 3,
        300u + static_cast<std::uint32_t>(arity_a * 10 + arity_b + 100 * static_cast<int>(split)));
    for (const testing::KernelChoice& kernels : testing::kKernelChoices) {
      SCOPED_TRACE(kernels.name);
      VolumeQuery query(
          {.use_avx2 = kernels.use_avx2, .use_avx512 = kernels.use_avx512, .force_avx512 = kernels.force_avx512});
      for (std::size_t k = 0; k < poses.size(); ++k) {
        expect_pose_matches_brute_force(query, *ta, *tb, la, lb, poses[k], static_cast<int>(k));
        EXPECT_GT(query.result().stats.overlapping_pairs, 300) << "not deep: the test would prove little";
      }
    }
  }
}

// The kernels the fast path may take on this machine: AVX-512 where the CPU has it and is AMD's (or
// with force_avx512), else AVX2 where it has that (neither on Windows builds), and always the
// baseline (SSE2); the options force the narrower ones.
TEST(VolumeQuery, TakesTheWidestKernelsTheCpuHas) {
#if defined(__x86_64__) && !defined(_WIN32)
  __builtin_cpu_init();
  const bool cpu_has_avx2 = __builtin_cpu_supports("avx2");
  const bool cpu_has_avx512 = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
                              __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512bw");
  const bool amd = __builtin_cpu_is("amd");
#else
  const bool cpu_has_avx2 = false, cpu_has_avx512 = false, amd = false;
#endif
  const bool default_avx512 = cpu_has_avx512 && amd;
  EXPECT_EQ(VolumeQuery().kernel_lanes(), default_avx512 ? 16 : cpu_has_avx2 ? 8 : 4);
  EXPECT_EQ(VolumeQuery().uses_avx512(), default_avx512);
  EXPECT_EQ(VolumeQuery().uses_avx2(), cpu_has_avx2 && !default_avx512);
  EXPECT_EQ(VolumeQuery({.force_avx512 = true}).kernel_lanes(), cpu_has_avx512 ? 16 : cpu_has_avx2 ? 8 : 4);
  EXPECT_EQ(VolumeQuery({.use_avx512 = false, .force_avx512 = true}).kernel_lanes(), cpu_has_avx2 ? 8 : 4);
  EXPECT_EQ(VolumeQuery({.use_avx512 = false}).kernel_lanes(), cpu_has_avx2 ? 8 : 4);
  EXPECT_EQ(VolumeQuery({.use_avx2 = false}).kernel_lanes(), 4);
  EXPECT_EQ(VolumeQuery({.use_avx2 = false, .use_avx512 = true}).kernel_lanes(), 4);
  EXPECT_FALSE(VolumeQuery({.reference_kernel = true, .use_avx2 = false}).uses_avx2());
}

// Leaf pairs at the lens kernel's branch points (coincident centres, containment and its boundary,
// lenses of equal and unequal radii, touching to the last bit, a hair apart), evaluated by the
// fast path with each kernel width: every stored pair must be sphere_overlap<float> of its two
// spheres bit for bit, and no overlapping pair may be missing.
TEST(VolumeQuery, FastKernelsEqualTheScalarLensAtItsBranchPoints) {
  std::vector<Sphere> la, lb;
  std::mt19937 rng(77);
  std::uniform_real_distribution<float> unit(0.f, 1.f);
  for (int i = 0; i < 40; ++i) {
    // A's spheres on a line, 10 apart; B's spheres around each
    const float x = 10.f * static_cast<float>(i), r = 0.5f + unit(rng);
    la.push_back({x, 0.f, 0.f, r});
    const float r2 = 0.2f + unit(rng);
    const float sum = r + r2, delta = std::abs(r - r2);
    const float ds[] = {0.f,
                        0.5f * delta,
                        delta,
                        std::nextafter(delta, 0.f),
                        std::nextafter(delta, sum),
                        0.5f * (delta + sum),
                        std::nextafter(sum, 0.f),
                        sum,
                        std::nextafter(sum, 2.f * sum),
                        std::numeric_limits<float>::min()};
    // each B sphere of a group along its own direction, offset so that they do not meet A's neighbours
    for (int k = 0; k < static_cast<int>(std::size(ds)); ++k) {
      const float dir = k % 2 == 0 ? 1.f : -1.f;
      if (k % 3 == 0)
        lb.push_back({x + dir * ds[k], 0.f, 0.f, r2});
      else
        lb.push_back({x, dir * ds[k], 0.f, k % 3 == 1 ? r2 : r});
    }
  }
  for (const int arity : {8, 4}) {
    const auto ta = build_sphere_tree(la, {.arity = arity});
    const auto tb = build_sphere_tree(lb, {.arity = arity});
    ASSERT_TRUE(ta && tb);
    for (const testing::KernelChoice& kernels : testing::kKernelChoices) {
      VolumeQuery q(
          {.use_avx2 = kernels.use_avx2, .use_avx512 = kernels.use_avx512, .force_avx512 = kernels.force_avx512});
      q.run(*ta, *tb, Pose{});
      std::set<std::pair<int, int>> got;
      for (const PairOverlap& p : q.pairs()) {
        got.emplace(p.leaf_a, p.leaf_b);
        const Sphere& a = la[static_cast<std::size_t>(p.leaf_a)];
        const Sphere& b = lb[static_cast<std::size_t>(p.leaf_b)];
        const float dx = b.x - a.x, dy = b.y - a.y, dz = b.z - a.z;
        const float d = std::sqrt(dx * dx + dy * dy + dz * dz);
        const SphereOverlap<float> o = sphere_overlap(d, a.radius, b.radius);
        const float inv = d > 0.f ? 1.f / d : 0.f;
        const float expected[8] = {o.volume,
                                   o.area,
                                   dx * inv,
                                   dy * inv,
                                   dz * inv,
                                   a.x + dx * inv * o.centroid_offset,
                                   a.y + dy * inv * o.centroid_offset,
                                   a.z + dz * inv * o.centroid_offset};
        const float actual[8] = {p.volume,    p.area,        p.normal[0],   p.normal[1],
                                 p.normal[2], p.centroid[0], p.centroid[1], p.centroid[2]};
        EXPECT_EQ(std::memcmp(expected, actual, sizeof expected), 0)
            << "pair (" << p.leaf_a << ", " << p.leaf_b << ") at d " << d << ": volume " << p.volume
            << " against " << o.volume << " (" << kernels.name << ")";
      }
      // every overlapping pair found (the scalar kernel decides, pair by pair)
      int overlapping = 0;
      for (std::size_t i = 0; i < la.size(); ++i)
        for (std::size_t j = 0; j < lb.size(); ++j) {
          const float dx = lb[j].x - la[i].x, dy = lb[j].y - la[i].y, dz = lb[j].z - la[i].z;
          if (sphere_overlap(std::sqrt(dx * dx + dy * dy + dz * dz), la[i].radius, lb[j].radius).volume >
              0.f) {
            ++overlapping;
            EXPECT_TRUE(got.count({static_cast<int>(i), static_cast<int>(j)}))
                << "pair " << i << ", " << j << " missing";
          }
        }
      EXPECT_EQ(static_cast<int>(got.size()), overlapping);
      EXPECT_GT(overlapping, 300) << "the cases hardly overlap: the test would prove little";
    }
  }
}

// The fast path (SIMD node tests and lens kernel) against the reference path (the scalar path it
// replaced): the same pairs in the same order with bit-identical volumes, areas, normals and
// centroids, the same near pairs of a contact margin, and totals equal up to summation order.
void expect_fast_equals_reference(float margin) {
  const auto la = make_packing(0.11, Shape::kBall, 81);
  const auto lb = make_packing(0.09, Shape::kRod, 82);
  // balanced trees, and k-means trees (leaves at several depths: leaf-against-inner visits)
  for (const auto& [arity_a, arity_b, split] :
       {std::tuple{8, 8, SphereTreeSplit::kBalanced}, std::tuple{8, 4, SphereTreeSplit::kBalanced},
        std::tuple{4, 4, SphereTreeSplit::kBalanced}, std::tuple{8, 8, SphereTreeSplit::kKMeans},
        std::tuple{8, 4, SphereTreeSplit::kKMeans}}) {
    const auto ta = build_sphere_tree(la, {.arity = arity_a, .split = split});
    const auto tb = build_sphere_tree(lb, {.arity = arity_b, .split = split});
    ASSERT_TRUE(ta && tb);
    // the fast path with the AVX2 kernels (where the CPU has them) and with the baseline kernels
    for (const testing::KernelChoice& kernels : testing::kKernelChoices) {
      SCOPED_TRACE(kernels.name);
      VolumeQuery fast(
          {.contact_margin = margin,
           .use_avx2 = kernels.use_avx2,
           .use_avx512 = kernels.use_avx512,
           .force_avx512 = kernels.force_avx512});
      VolumeQuery reference({.contact_margin = margin, .reference_kernel = true});
      for (const Pose& pose : testing::deep_poses(
               *ta, *tb, 4,
               400u + static_cast<std::uint32_t>(arity_a * 10 + arity_b + 100 * static_cast<int>(split)))) {
        const VolumeQueryResult f = fast.run(*ta, *tb, pose);
        const VolumeQueryResult& r = reference.run(*ta, *tb, pose);
        ASSERT_GT(r.pair_count, 150);
        ASSERT_EQ(f.pair_count, r.pair_count);
        ASSERT_EQ(f.stats.overlapping_pairs, r.stats.overlapping_pairs);
        ASSERT_EQ(f.near_pairs, r.near_pairs);
        if (margin > 0.f) {
          EXPECT_GT(r.near_pairs, 0) << "the margin found no near pairs: the test would prove little";
        }
        for (int i = 0; i < r.pair_count; ++i) {
          const PairOverlap& pf = fast.pairs()[static_cast<std::size_t>(i)];
          const PairOverlap& pr = reference.pairs()[static_cast<std::size_t>(i)];
          ASSERT_EQ(std::memcmp(&pf, &pr, sizeof(PairOverlap)), 0)
              << "pair " << i << ": (" << pf.leaf_a << ", " << pf.leaf_b << ") volume " << pf.volume
              << " against (" << pr.leaf_a << ", " << pr.leaf_b << ") volume " << pr.volume;
        }
        // summed in the same order: equal, not merely close
        testing::expect_identical_totals(f, r);
      }
    }
  }
}

TEST(VolumeQuery, FastPathEqualsReferencePathOnDeepPoses) { expect_fast_equals_reference(0.f); }

TEST(VolumeQuery, FastPathEqualsReferencePathWithContactMargin) { expect_fast_equals_reference(0.02f); }

TEST(VolumeQuery, PrunesMostLeafPairs) {
  // the traversal must test far fewer leaf pairs than brute force (n_a * n_b); the k-means tree's
  // tight leaf-level spheres keep within 50 tests per overlapping pair, the balanced tree (the
  // default: eight leaves under each leaf-level node) tests more leaf pairs in its full SIMD blocks
  // but visits fewer node pairs, for the same pairs
  const auto la = make_packing(0.08, Shape::kBall, 51);
  const auto balanced = build_sphere_tree(la);
  const auto kmeans = build_sphere_tree(la, {.split = SphereTreeSplit::kKMeans});
  ASSERT_TRUE(balanced && kmeans);
  const Pose pose{quat_from_axis_angle({0, 1, 0}, 0.5), {1.5, 0, 0}};
  VolumeQuery q;
  const VolumeQueryResult b = q.run(*balanced, *balanced, pose);
  const VolumeQueryResult& k = q.run(*kmeans, *kmeans, pose);
  ASSERT_GT(k.stats.overlapping_pairs, 0);
  const double brute = static_cast<double>(la.size()) * static_cast<double>(la.size());
  EXPECT_LT(static_cast<double>(k.stats.leaf_pairs_tested), 0.01 * brute);
  EXPECT_LT(static_cast<double>(b.stats.leaf_pairs_tested), 0.01 * brute);
  EXPECT_LT(k.stats.leaf_pairs_tested, 50 * k.stats.overlapping_pairs);
  EXPECT_EQ(b.stats.overlapping_pairs, k.stats.overlapping_pairs);
  EXPECT_LT(b.stats.node_pairs_visited, k.stats.node_pairs_visited);
}

}  // namespace
}  // namespace uh::collette
