// find_contact_patches() against the brute-force definition of a patch: the connected components
// of the link graph over all pairs (two pairs linked when their lens centroids are closer than the
// larger of their link distances), found by union-find over every pair of pairs. The boxes the
// function grows may join regions whose boxes come close (documented), so the regions here are far
// apart compared with their extent: there both must agree exactly.
#include "uh/forcecomp/contact_patches.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <vector>

#include "uh/core/split_mix.hpp"

namespace uh::forcecomp {
namespace {

struct Region {
  std::vector<SpherePairContact> pairs;
};

// A region: a random walk of `n` lens centroids around `centre`, each step shorter than the link
// distance of both pairs it joins (so the region is connected), radii 0.5-1.5 mm.
Region walk(core::SplitMix64& random, const Vec3& centre, int n, float volume_scale) {
  Region r;
  Vec3 p = centre;
  for (int i = 0; i < n; ++i) {
    SpherePairContact c;
    const auto radius = static_cast<float>(0.0005 + 0.001 * random.uniform());
    c.sphere_a_local.radius = radius;
    c.sphere_b_local.radius = radius * 1.5f;
    c.volume = volume_scale * static_cast<float>(0.5 + random.uniform());
    if (i > 0) {
      // step below 2 x 0.5 mm, the smallest link distance any pair here has
      const Vec3 d{random.uniform() - 0.5, random.uniform() - 0.5, random.uniform() - 0.5};
      p += (0.0009 * random.uniform() / std::max(norm(d), 1e-9)) * d;
    }
    c.centroid_world[0] = static_cast<float>(p.x);
    c.centroid_world[1] = static_cast<float>(p.y);
    c.centroid_world[2] = static_cast<float>(p.z);
    r.pairs.push_back(c);
  }
  return r;
}

double link_of(const SpherePairContact& p) {
  return kPatchLinkRadii * static_cast<double>(std::min(p.sphere_a_local.radius, p.sphere_b_local.radius));
}

Vec3 centroid(const SpherePairContact& p) {
  return {static_cast<double>(p.centroid_world[0]), static_cast<double>(p.centroid_world[1]),
          static_cast<double>(p.centroid_world[2])};
}

// the reference: union-find over every pair of pairs
std::vector<int> components(const std::vector<SpherePairContact>& pairs) {
  std::vector<int> parent(pairs.size());
  std::iota(parent.begin(), parent.end(), 0);
  const auto root = [&](int i) {
    while (parent[static_cast<std::size_t>(i)] != i) i = parent[static_cast<std::size_t>(i)];
    return i;
  };
  for (std::size_t i = 0; i < pairs.size(); ++i)
    for (std::size_t j = i + 1; j < pairs.size(); ++j)
      if (norm(centroid(pairs[i]) - centroid(pairs[j])) < std::max(link_of(pairs[i]), link_of(pairs[j])))
        parent[static_cast<std::size_t>(root(static_cast<int>(i)))] = root(static_cast<int>(j));
  std::vector<int> out(pairs.size());
  for (std::size_t i = 0; i < pairs.size(); ++i) out[i] = root(static_cast<int>(i));
  return out;
}

void shuffle(core::SplitMix64& random, std::vector<SpherePairContact>& pairs) {
  for (int i = static_cast<int>(pairs.size()) - 1; i > 0; --i)
    std::swap(pairs[static_cast<std::size_t>(i)], pairs[static_cast<std::size_t>(random.below(i + 1))]);
}

TEST(ContactPatches, SeparateRegionsAreTheLinkGraphsComponents) {
  core::SplitMix64 random{11};
  for (int trial = 0; trial < 200; ++trial) {
    const int regions = 1 + trial % kMaxContactPatches;
    std::vector<SpherePairContact> pairs;
    for (int k = 0; k < regions; ++k) {
      // 5-40 steps under 0.9 mm: a region spans under 36 mm; regions are 0.1 m apart
      const Vec3 centre{0.1 * k, 0.05 * (k % 2), -0.02 * k};
      const Region r = walk(random, centre, 5 + random.below(36), 1e-9f);
      pairs.insert(pairs.end(), r.pairs.begin(), r.pairs.end());
    }
    shuffle(random, pairs);
    const std::vector<int> reference = components(pairs);
    std::vector<int> roots = reference;
    std::sort(roots.begin(), roots.end());
    ASSERT_EQ(std::unique(roots.begin(), roots.end()) - roots.begin(), regions)
        << "trial " << trial << ": the generated regions must be the graph's components";

    const ContactPatches patches = find_contact_patches(pairs);
    ASSERT_EQ(patches.count, regions) << "trial " << trial;
    double volume = 0.0;
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      volume += static_cast<double>(pairs[i].volume);
      const std::int32_t pi = patches.patch_of(pairs[i]);
      ASSERT_GE(pi, 0);
      ASSERT_LT(pi, patches.count);
      for (std::size_t j = i + 1; j < pairs.size(); ++j)
        ASSERT_EQ(pi == patches.patch_of(pairs[j]), reference[i] == reference[j])
            << "trial " << trial << ": pairs " << i << " and " << j;
    }
    double patch_volume = 0.0;
    for (std::int32_t p = 0; p < patches.count; ++p) patch_volume += patches.patch[p].volume;
    EXPECT_NEAR(patch_volume, volume, 1e-9 * volume) << "the patches hold every pair's volume";
  }
}

// Six regions, two of them small: the two smallest join their nearest patches, no region is split,
// and each of the four large ones keeps a patch of its own.
TEST(ContactPatches, BeyondTheMostTheSmallestRegionsJoinTheirNearest) {
  core::SplitMix64 random{5};
  const float scales[6] = {300.f, 1.f, 200.f, 400.f, 2.f, 100.f};  // x 1e-9 per pair
  std::vector<std::vector<SpherePairContact>> regions;
  std::vector<SpherePairContact> pairs;
  for (int k = 0; k < 6; ++k) {
    const Region r = walk(random, {0.1 * k, 0.0, 0.0}, 20, scales[k] * 1e-9f);
    regions.push_back(r.pairs);
    pairs.insert(pairs.end(), r.pairs.begin(), r.pairs.end());
  }
  shuffle(random, pairs);
  const ContactPatches patches = find_contact_patches(pairs);
  ASSERT_EQ(patches.count, kMaxContactPatches);
  std::array<std::int32_t, 6> of_region{};
  for (std::size_t k = 0; k < regions.size(); ++k) {
    const auto& r = regions[k];
    std::int32_t p = -1;
    for (const SpherePairContact& c : r) {
      const std::int32_t q = patches.patch_of(c);
      if (p < 0) p = q;
      ASSERT_EQ(q, p) << "a region is never split";
    }
    of_region[k] = p;
  }
  const std::int32_t large[4] = {of_region[0], of_region[2], of_region[3], of_region[5]};
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) EXPECT_NE(large[i], large[j]) << "large regions " << i << ", " << j;
}

TEST(ContactPatches, PairsWithoutVolumeMakeNoPatch) {
  EXPECT_EQ(find_contact_patches({}).count, 0);
  core::SplitMix64 random{3};
  Region r = walk(random, {0, 0, 0}, 10, 0.f);  // the contact margin's pairs: volume 0
  for (SpherePairContact& c : r.pairs) c.volume = 0.f;
  EXPECT_EQ(find_contact_patches(r.pairs).count, 0);
}

}  // namespace
}  // namespace uh::forcecomp
