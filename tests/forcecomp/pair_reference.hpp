#pragma once
// Brute-force reference for the forcecomp tests: builds SpherePairContacts straight from the
// overlap geometry, the way a collision query would, without any tree, with the independent lens
// reference (tests/support/lens_reference.hpp) rather than the kernel under test.

#include <vector>

#include "lens_reference.hpp"
#include "uh/core/contact.hpp"
#include "uh/core/math.hpp"
#include "uh/core/split_mix.hpp"

namespace uh::forcecomp::test {

inline Vec3 centre_of(const Sphere& s) {
  return {static_cast<double>(s.x), static_cast<double>(s.y), static_cast<double>(s.z)};
}

inline Sphere sphere(double x, double y, double z, double r) {
  return {static_cast<float>(x), static_cast<float>(y), static_cast<float>(z), static_cast<float>(r)};
}

/// `count` spheres with centres in [-0.5, 0.5]^3 and radii in [0.08, 0.2]: packings that overlap deeply.
inline std::vector<Sphere> random_spheres(core::SplitMix64& rng, int count) {
  std::vector<Sphere> out;
  for (int i = 0; i < count; ++i) {
    const double x = rng.uniform() - 0.5, y = rng.uniform() - 0.5, z = rng.uniform() - 0.5;
    out.push_back(sphere(x, y, z, 0.08 + 0.12 * rng.uniform()));
  }
  return out;
}

/// The pair record of spheres a (in A) and b (in B) at the given poses; volume 0 when apart.
inline SpherePairContact make_pair(const Sphere& a, const Pose& world_from_a, const Sphere& b, const Pose& world_from_b,
                                   int leaf_a = 0, int leaf_b = 0) {
  SpherePairContact p;
  const Vec3 ca = transform_point(world_from_a, centre_of(a));
  const Vec3 cb = transform_point(world_from_b, centre_of(b));
  const double ra = static_cast<double>(a.radius);
  const double rb = static_cast<double>(b.radius);
  const double d = norm(cb - ca);
  const Vec3 u = normalized(cb - ca);
  const uh::test::LensReference lens = uh::test::lens_reference(d, ra, rb);
  const Vec3 c = ca + lens.centroid_offset * u;
  p.volume = static_cast<float>(lens.volume);
  p.area = static_cast<float>(lens.area);
  p.normal_world[0] = static_cast<float>(u.x);
  p.normal_world[1] = static_cast<float>(u.y);
  p.normal_world[2] = static_cast<float>(u.z);
  p.centroid_world[0] = static_cast<float>(c.x);
  p.centroid_world[1] = static_cast<float>(c.y);
  p.centroid_world[2] = static_cast<float>(c.z);
  p.sphere_a_local = a;
  p.sphere_b_local = b;
  p.leaf_a = leaf_a;
  p.leaf_b = leaf_b;
  return p;
}

/// All overlapping pairs of two sphere sets, by testing every pair.
inline std::vector<SpherePairContact> brute_force_pairs(const std::vector<Sphere>& a, const Pose& world_from_a,
                                                        const std::vector<Sphere>& b, const Pose& world_from_b) {
  std::vector<SpherePairContact> out;
  for (std::size_t i = 0; i < a.size(); ++i) {
    for (std::size_t j = 0; j < b.size(); ++j) {
      SpherePairContact p =
          make_pair(a[i], world_from_a, b[j], world_from_b, static_cast<int>(i), static_cast<int>(j));
      if (p.volume > 0.f) out.push_back(p);
    }
  }
  return out;
}

}  // namespace uh::forcecomp::test
