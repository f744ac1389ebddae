#pragma once
// Leaf-set generators and brute-force references shared by the sphere-tree tests.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "lens_reference.hpp"
#include "uh/collette/sphere_tree.hpp"
#include "uh/collette/volume_query.hpp"
#include "uh/core/contact.hpp"
#include "uh/core/math.hpp"
#include "uh/core/split_mix.hpp"

namespace uh::collette::testing {

enum class Shape { kBall, kBox, kRod };

/// Non-overlapping spheres on a jittered grid of spacing `h` inside a shape of size ~1 centred at
/// `offset`; radii vary in [0.15 h, 0.5 h - jitter] so that the spheres never overlap.
inline std::vector<Sphere> make_packing(double h, Shape shape, std::uint32_t seed, Vec3 offset = {}) {
  core::SplitMix64 rng{seed};
  const auto u = [](core::SplitMix64& g) { return g.uniform(); };
  const double jitter = 0.1 * h;
  std::vector<Sphere> out;
  const int n = static_cast<int>(std::ceil(1.0 / h));
  for (int i = -n; i <= n; ++i)
    for (int j = -n; j <= n; ++j)
      for (int k = -n; k <= n; ++k) {
        const Vec3 p{i * h, j * h, k * h};
        bool inside = false;
        switch (shape) {
          case Shape::kBall: inside = norm(p) <= 1.0; break;
          case Shape::kBox: inside = std::abs(p.x) <= 1.0 && std::abs(p.y) <= 0.6 && std::abs(p.z) <= 0.4; break;
          case Shape::kRod: inside = std::abs(p.x) <= 1.0 && p.y * p.y + p.z * p.z <= 0.09; break;
        }
        if (!inside) continue;
        const Vec3 c = p + Vec3{(2 * u(rng) - 1) * jitter, (2 * u(rng) - 1) * jitter, (2 * u(rng) - 1) * jitter} + offset;
        const double r = 0.15 * h + u(rng) * (0.5 * h - jitter - 0.15 * h);
        out.push_back({static_cast<float>(c.x), static_cast<float>(c.y), static_cast<float>(c.z), static_cast<float>(r)});
      }
  return out;
}

/// A uniformly random rotation (a normalised Gaussian quaternion) and a shift in [-max_shift, max_shift)^3.
inline Pose random_pose(core::SplitMix64& rng, double max_shift) {
  const auto u = [&] { return max_shift * (2.0 * rng.uniform() - 1.0); };
  const double w = rng.normal(), x = rng.normal(), y = rng.normal(), z = rng.normal();
  const Quat q = normalized(Quat{w, x, y, z});
  const double px = u(), py = u(), pz = u();
  return {q, {px, py, pz}};
}

inline Vec3 centre(const Sphere& s) {
  return {static_cast<double>(s.x), static_cast<double>(s.y), static_cast<double>(s.z)};
}

/// Brute force over all leaf pairs, in double, A frame, with the independent lens reference
/// (tests/support/lens_reference.hpp), not the kernel the queries use.
struct BruteVolume {
  double volume = 0.0;
  Vec3 normal_sum{};
  Vec3 centroid_sum{};  // sum of volume * centroid
  Vec3 gradient{};      // sum of dV/dd * normal = -sum of disk area * normal
  std::vector<std::pair<int, int>> pairs;
  std::vector<double> pair_volumes;
};

inline BruteVolume brute_volume(const std::vector<Sphere>& a, const std::vector<Sphere>& b, const Pose& b_in_a) {
  BruteVolume r;
  for (int j = 0; j < static_cast<int>(b.size()); ++j) {
    const Vec3 cb = transform_point(b_in_a, centre(b[static_cast<std::size_t>(j)]));
    const double rb = static_cast<double>(b[static_cast<std::size_t>(j)].radius);
    for (int i = 0; i < static_cast<int>(a.size()); ++i) {
      const Vec3 ca = centre(a[static_cast<std::size_t>(i)]);
      const double ra = static_cast<double>(a[static_cast<std::size_t>(i)].radius);
      const double d = norm(cb - ca);
      if (d >= ra + rb) continue;  // apart (the reference gives no volume): skipped for speed
      const uh::test::LensReference lens = uh::test::lens_reference(d, ra, rb);
      const double v = lens.volume;
      if (!(v > 0.0)) continue;
      const Vec3 n = normalized(cb - ca);
      r.volume += v;
      r.normal_sum += v * n;
      r.centroid_sum += v * (ca + n * lens.centroid_offset);
      r.gradient += -lens.area * n;
      r.pairs.emplace_back(i, j);
      r.pair_volumes.push_back(v);
    }
  }
  return r;
}

/// Smallest gap between a sphere of a and one of b (negative when overlapping).
inline double brute_gap(const std::vector<Sphere>& a, const std::vector<Sphere>& b, const Pose& b_in_a) {
  double best = 1e300;
  for (const Sphere& sb : b) {
    const Vec3 cb = transform_point(b_in_a, centre(sb));
    for (const Sphere& sa : a)
      best = std::min(best, norm(cb - centre(sa)) - static_cast<double>(sa.radius) - static_cast<double>(sb.radius));
  }
  return best;
}

// Deep poses as in the query benchmark: B at random orientations, each moved along a random
// direction until the packings overlap by half of what they overlap when centred on each other
// (the benchmark's bunny packings are dense, 0.86, and there a quarter of the packing volume is
// about half of it; the test packings are sparse). Bisection on the reference path's volume.
inline std::vector<Pose> deep_poses(const SphereTree& ta, const SphereTree& tb, int count,
                                    std::uint32_t seed) {
  core::SplitMix64 rng{seed};
  const auto g = [](core::SplitMix64& r) { return r.normal(); };
  VolumeQuery q({.collect_pairs = false, .reference_kernel = true});
  const Vec3 ca = centre({ta.root().x, ta.root().y, ta.root().z, 0.f});
  const Vec3 cb = centre({tb.root().x, tb.root().y, tb.root().z, 0.f});
  const double reach = static_cast<double>(ta.root().radius + tb.root().radius);
  std::vector<Pose> out;
  while (static_cast<int>(out.size()) < count) {
    const Quat rot = normalized(Quat{g(rng), g(rng), g(rng), g(rng)});
    const Vec3 dir = normalized(Vec3{g(rng), g(rng), g(rng)});
    const auto at = [&](double s) { return Pose{rot, ca + s * dir - rotate(rot, cb)}; };
    const auto volume = [&](double s) { return q.run(ta, tb, at(s)).total_volume; };
    const double target = 0.5 * volume(0.0);
    double lo = 0.0, hi = reach;
    for (int i = 0; i < 30; ++i) {
      const double mid = 0.5 * (lo + hi);
      (volume(mid) > target ? lo : hi) = mid;
    }
    out.push_back(at(lo));
  }
  return out;
}

// Two runs' totals equal, not merely close (the same pairs summed in the same order).
inline void expect_identical_totals(const VolumeQueryResult& got, const VolumeQueryResult& want) {
  EXPECT_EQ(got.total_volume, want.total_volume);
  const Vec3 pairs[3][2] = {{got.weighted_normal_sum, want.weighted_normal_sum},
                            {got.volume_gradient, want.volume_gradient},
                            {got.volume_centroid, want.volume_centroid}};
  for (const auto& [g, w] : pairs) {
    EXPECT_EQ(g.x, w.x);
    EXPECT_EQ(g.y, w.y);
    EXPECT_EQ(g.z, w.z);
  }
}

// The volume query's fast-path kernel widths a test runs: the widest the CPU has (AVX-512 where it
// has it, also where the default would not take it), AVX2 (where it has it) and the baseline. On a
// CPU without them the wider choices take the widest it has, so every choice is still a real query.
struct KernelChoice {
  bool use_avx2, use_avx512, force_avx512;
  const char* name;
};
inline constexpr KernelChoice kKernelChoices[] = {{true, true, true, "widest kernels"},
                                                  {true, false, false, "AVX2 kernels"},
                                                  {false, false, false, "baseline kernels"}};

}  // namespace uh::collette::testing
