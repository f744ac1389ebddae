// The lens kernel (sphere_overlap.hpp) against references that do not share its formulas:
//  - quadruple precision (__float128, 113-bit mantissa) integration of the overlap's cross-section
//    pi * min(r1^2 - z^2, r2^2 - (d - z)^2) along the centre line, piece by piece between the
//    radical plane and the sphere ends (Simpson's rule, exact for these quadratic and cubic
//    integrands); its derivative in d by a central difference in quadruple precision;
//  - Monte Carlo sampling for volume and centroid.
// Errors are bounded in units of the kernel type's epsilon, for float and double.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "uh/core/math.hpp"
#include "uh/core/sphere_overlap.hpp"

namespace uh {
namespace {

// __extension__: quadruple precision is a GCC/Clang extension on x86-64 (software arithmetic, no library)
__extension__ typedef __float128 Quad;
static_assert(sizeof(Quad) == 16, "the reference needs quadruple precision");

// pi to ~106 bits as the sum of two doubles (no quad literal or libquadmath needed)
const Quad kPiQ = static_cast<Quad>(3.141592653589793) + static_cast<Quad>(1.2246467991473532e-16);

struct Reference {
  Quad volume = 0;
  Quad area = 0;             // pi a^2, from the radical plane's position
  Quad disk_offset = 0;      // the radical plane
  Quad centroid_offset = 0;  // first moment / volume
  Quad cap_surface = 0;      // 2 pi (r1 h1 + r2 h2): the lens's surface, bounds dV/dr1 + dV/dr2
};

// cross-section of the overlap at z (sphere 1 centred at 0, sphere 2 at d, both on the z axis)
Quad section(Quad z, Quad d, Quad r1, Quad r2) {
  const Quad f1 = r1 * r1 - z * z;
  const Quad f2 = r2 * r2 - (d - z) * (d - z);
  return kPiQ * std::max(Quad(0), std::min(f1, f2));
}

// integral of section(z) and z * section(z) over [lo, hi], on which one of the two profiles is the
// smaller throughout: Simpson's rule, exact for polynomials up to degree 3
void integrate(Quad lo, Quad hi, Quad d, Quad r1, Quad r2, Quad& volume, Quad& moment) {
  if (!(hi > lo)) return;
  const Quad mid = (lo + hi) / 2, w = (hi - lo) / 6;
  const Quad a = section(lo, d, r1, r2), m = section(mid, d, r1, r2), b = section(hi, d, r1, r2);
  volume += w * (a + 4 * m + b);
  moment += w * (lo * a + 4 * mid * m + hi * b);
}

Reference reference(Quad d, Quad r1, Quad r2) {
  Reference r;
  const Quad lo = std::max(-r1, d - r2), hi = std::min(r1, d + r2);
  if (!(hi > lo)) {
    r.disk_offset = r.centroid_offset = d * r1 / (r1 + r2);
    return r;
  }
  // the profiles cross where r1^2 - z^2 = r2^2 - (d - z)^2
  const Quad x = d > 0 ? (d * d + r1 * r1 - r2 * r2) / (2 * d) : Quad(0);
  Quad volume = 0, moment = 0;
  if (d > 0 && x > lo && x < hi) {
    integrate(lo, x, d, r1, r2, volume, moment);
    integrate(x, hi, d, r1, r2, volume, moment);
    r.area = kPiQ * (r1 * r1 - x * x);
    r.disk_offset = x;
    r.cap_surface = 2 * kPiQ * (r1 * (r1 - x) + r2 * (r2 - (d - x)));
  } else {
    integrate(lo, hi, d, r1, r2, volume, moment);  // containment: the smaller sphere throughout
    r.disk_offset = moment / volume;
    const Quad rmin = std::min(r1, r2);
    r.cap_surface = 4 * kPiQ * rmin * rmin;
  }
  r.volume = volume;
  r.centroid_offset = moment / volume;
  return r;
}

double to_double(Quad q) { return static_cast<double>(q); }

template <typename Real>
constexpr double kEps = static_cast<double>(std::numeric_limits<Real>::epsilon());

// Checks the kernel at (d, r1, r2), all exactly representable in Real. The bounds are those of a
// backward-stable evaluation: a few ulps of the result plus what moving d, r1, r2 by a few ulps
// changes (the lens surface bounds the volume's sensitivity to them).
template <typename Real>
void expect_close_to_reference(Real d, Real r1, Real r2, double* worst_volume_ulps = nullptr) {
  const SphereOverlap<Real> k = sphere_overlap(d, r1, r2);
  const Reference ref = reference(static_cast<Quad>(d), static_cast<Quad>(r1), static_cast<Quad>(r2));
  const double eps = kEps<Real>;
  const double scale = static_cast<double>(r1) + static_cast<double>(r2);
  const double v = to_double(ref.volume);
  const double v_tol = 8.0 * eps * v + 4.0 * eps * scale * to_double(ref.cap_surface);
  const auto where = [&] {
    return ::testing::Message() << "d=" << static_cast<double>(d) << " r1=" << static_cast<double>(r1)
                                << " r2=" << static_cast<double>(r2) << " ("
                                << (sizeof(Real) == 4 ? "float" : "double") << ")";
  };
  EXPECT_NEAR(static_cast<double>(k.volume), v, v_tol) << where();
  EXPECT_NEAR(static_cast<double>(k.area), to_double(ref.area),
              8.0 * eps * to_double(ref.area) + 8.0 * eps * kPi * scale * scale)
      << where();
  EXPECT_NEAR(static_cast<double>(k.disk_offset), to_double(ref.disk_offset), 8.0 * eps * scale) << where();
  EXPECT_NEAR(static_cast<double>(k.centroid_offset), to_double(ref.centroid_offset), 8.0 * eps * scale)
      << where();
  EXPECT_GE(k.volume, Real(0));
  EXPECT_TRUE(std::isfinite(static_cast<double>(k.centroid_offset)) &&
              std::isfinite(static_cast<double>(k.area)));
  if (worst_volume_ulps != nullptr && v > 0.0)
    *worst_volume_ulps =
        std::max(*worst_volume_ulps, std::abs(static_cast<double>(k.volume) - v) / (eps * v));
}

template <typename Real>
void sweep_equal_radii(Real r) {
  double worst = 0.0;
  // d / r from 1e-9 to 2, 20 points a decade
  for (int i = 0; i <= 186; ++i) {
    const double ratio = std::min(2.0, std::pow(10.0, -9.0 + i / 20.0));
    const Real d = static_cast<Real>(ratio * static_cast<double>(r));
    expect_close_to_reference(d, r, r, &worst);
  }
  // the equal-radii volume is well conditioned everywhere but at touching: a few ulps suffice
  EXPECT_LT(worst, 64.0) << "largest volume error in ulps over d/r in [1e-9, 2]";
}

TEST(SphereOverlap, EqualRadiiMatchQuadPrecisionFromTinyOffsetsToTouching) {
  for (float r : {1.0f, 0.37f, 1e-3f, 250.0f}) sweep_equal_radii<float>(r);
  for (double r : {1.0, 0.37, 1e-3, 250.0}) sweep_equal_radii<double>(r);
}

TEST(SphereOverlap, TinyOffsetOfEqualSpheresLosesExactlyTheDiskVolume) {
  // V(d) = 4/3 pi r^3 - pi r^2 d + pi d^3 / 12 for equal spheres: at d = 1e-6 r the textbook
  // expansion cancels to garbage in float (it gave more than the sphere's volume); here the loss
  // is resolved to a few ulps of the volume
  const float r = 1.0f;
  for (float d : {1e-7f, 1e-6f, 1e-5f}) {
    const double full = 4.0 / 3.0 * kPi;
    const double expected =
        full - kPi * static_cast<double>(d) + kPi * std::pow(static_cast<double>(d), 3) / 12.0;
    const auto k = sphere_overlap(d, r, r);
    EXPECT_NEAR(static_cast<double>(k.volume), expected, 4.0 * kEps<float> * full) << "d=" << d;
    EXPECT_LE(static_cast<double>(k.volume), static_cast<double>(sphere_overlap(0.f, r, r).volume));
  }
}

template <typename Real>
void random_cases(std::uint32_t seed, int count) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> ratio(0.01, 1.0), along(0.0, 1.0);
  double worst = 0.0;
  for (int n = 0; n < count; ++n) {
    const Real r1 = static_cast<Real>(ratio(rng));
    const Real r2 = static_cast<Real>(ratio(rng) * static_cast<double>(r1) * (n % 2 ? 1.0 : 30.0));
    const double lo = std::abs(static_cast<double>(r1) - static_cast<double>(r2));
    const double hi = static_cast<double>(r1) + static_cast<double>(r2);
    const Real d = static_cast<Real>(lo + along(rng) * (hi - lo) * 1.1);  // lens, containment and apart
    expect_close_to_reference(d, r1, r2, &worst);
  }
  ::testing::Test::RecordProperty(sizeof(Real) == 4 ? "worst_float_volume_ulps" : "worst_double_volume_ulps",
                                  std::to_string(worst));
}

TEST(SphereOverlap, RandomRadiiAndDistancesMatchQuadPrecision) {
  random_cases<float>(1, 4000);
  random_cases<double>(2, 4000);
}

template <typename Real>
void boundaries(Real r1, Real r2) {
  const Real inf = std::numeric_limits<Real>::infinity();
  const Real inner = std::abs(r1 - r2), outer = r1 + r2;
  // a few ulps either side of the containment and the touching boundary
  std::vector<Real> ds;
  for (Real b : {inner, outer}) {
    Real lo = b, hi = b;
    for (int i = 0; i < 8; ++i) {
      ds.push_back(lo);
      ds.push_back(hi);
      lo = std::nextafter(lo, Real(0));
      hi = std::nextafter(hi, inf);
    }
  }
  for (Real d : ds) expect_close_to_reference(d, r1, r2);
  // continuity across the containment boundary: the volume next to it is the contained one to
  // within the change one ulp of d makes (|dV/dd| = 0 there), and the area starts at zero
  const Real contained = sphere_overlap(inner, r1, r2).volume;
  const auto above = sphere_overlap(std::nextafter(inner, inf), r1, r2);
  EXPECT_NEAR(static_cast<double>(above.volume), static_cast<double>(contained),
              8.0 * kEps<Real> * static_cast<double>(contained));
  EXPECT_LE(above.volume, contained);
  // and the touching one: volume and area tend to zero
  const auto below = sphere_overlap(std::nextafter(outer, Real(0)), r1, r2);
  EXPECT_LT(static_cast<double>(below.volume), 1e-6 * static_cast<double>(contained));
}

TEST(SphereOverlap, ContainmentAndTouchingBoundariesAreContinuous) {
  boundaries<float>(1.0f, 0.5f);
  boundaries<float>(0.3f, 1.0f);
  boundaries<float>(1.0f, 0.999f);
  boundaries<double>(1.0, 0.5);
  boundaries<double>(0.3, 1.0);
  boundaries<double>(1.0, 0.999);
}

TEST(SphereOverlap, VolumeNeverRisesWithDistanceAndNeverExceedsTheSmallerSphere) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> radius(0.05f, 1.0f);
  for (int n = 0; n < 200; ++n) {
    const float r1 = radius(rng), r2 = radius(rng);
    const float full = sphere_overlap(0.f, r1, r2).volume;
    float previous = full;
    for (int i = 0; i <= 2000; ++i) {
      const float d = (r1 + r2) * static_cast<float>(i) / 2000.f;
      const float v = sphere_overlap(d, r1, r2).volume;
      ASSERT_LE(v, full) << "r1=" << r1 << " r2=" << r2 << " d=" << d;
      // monotone up to rounding (a few ulps of the volume)
      ASSERT_LE(v, previous + 8.f * std::numeric_limits<float>::epsilon() * full)
          << "r1=" << r1 << " r2=" << r2 << " d=" << d;
      previous = v;
    }
  }
}

TEST(SphereOverlap, AreaIsMinusTheDerivativeOfTheVolume) {
  // central difference of the quad-precision volume against the kernel's area (double)
  for (const auto& [d, r1, r2] : std::vector<std::array<double, 3>>{{1.5, 1, 1},
                                                                    {0.4, 1, 1},
                                                                    {1.2, 1, 0.5},
                                                                    {0.8, 0.3, 1},
                                                                    {0.6, 1, 0.5},
                                                                    {1.9, 1.2, 0.9},
                                                                    {1e-6, 1, 1}}) {
    const Quad h = Quad(1e-12);
    const Quad slope = (reference(Quad(d) + h, Quad(r1), Quad(r2)).volume -
                        reference(Quad(d) - h, Quad(r1), Quad(r2)).volume) /
                       (2 * h);
    EXPECT_NEAR(sphere_overlap(d, r1, r2).area, -to_double(slope), 1e-9 * kPi * (r1 + r2) * (r1 + r2))
        << "d=" << d;
  }
  // and zero where the volume is flat: apart, contained
  EXPECT_EQ(sphere_overlap(2.5, 1.0, 1.0).area, 0.0);
  EXPECT_EQ(sphere_overlap(0.2, 1.0, 0.5).area, 0.0);
}

// Monte Carlo over the bounding box of the smaller sphere: volume and centroid of the overlap.
struct MonteCarlo {
  double volume;
  double centroid_offset;  // along the centre line from c1
};
MonteCarlo monte_carlo_lens(double d, double r1, double r2, int samples, std::uint32_t seed) {
  std::mt19937 rng(seed);
  const double rs = std::min(r1, r2);
  const double cx = r1 <= r2 ? 0.0 : d;  // centre of the smaller sphere on the x axis
  std::uniform_real_distribution<double> u(-rs, rs);
  int inside = 0;
  double sum_x = 0.0;
  for (int s = 0; s < samples; ++s) {
    const double x = cx + u(rng), y = u(rng), z = u(rng);
    if (x * x + y * y + z * z <= r1 * r1 && (x - d) * (x - d) + y * y + z * z <= r2 * r2) {
      ++inside;
      sum_x += x;
    }
  }
  const double box = 8.0 * rs * rs * rs;
  return {box * inside / samples, inside > 0 ? sum_x / inside : 0.0};
}

TEST(SphereOverlap, VolumeAndCentroidMatchMonteCarlo) {
  struct Case {
    double d, r1, r2;
  };
  const Case cases[] = {{1.5, 1.0, 1.0}, {0.4, 1.0, 1.0}, {1.2, 1.0, 0.5},
                        {0.8, 0.3, 1.0}, {0.2, 1.0, 0.5}, {1.9, 1.2, 0.9}};
  std::uint32_t seed = 1;
  for (const Case& c : cases) {
    const MonteCarlo mc = monte_carlo_lens(c.d, c.r1, c.r2, 400000, seed++);
    const auto k = sphere_overlap(c.d, c.r1, c.r2);
    const double scale = 4.0 / 3.0 * kPi * std::pow(std::min(c.r1, c.r2), 3);
    EXPECT_NEAR(k.volume, mc.volume, 0.01 * scale) << "d=" << c.d << " r1=" << c.r1 << " r2=" << c.r2;
    EXPECT_NEAR(k.centroid_offset, mc.centroid_offset, 0.01 * std::max(c.r1, c.r2))
        << "d=" << c.d << " r1=" << c.r1 << " r2=" << c.r2;
  }
}

TEST(SphereOverlap, CoincidentAndNonFiniteDistancesGiveFiniteResults) {
  for (float d : {0.f, std::numeric_limits<float>::denorm_min(), std::numeric_limits<float>::min(), 1e-30f}) {
    const auto k = sphere_overlap(d, 1.f, 1.f);
    EXPECT_TRUE(std::isfinite(k.volume) && std::isfinite(k.area) && std::isfinite(k.centroid_offset) &&
                std::isfinite(k.disk_offset))
        << "d=" << d;
    EXPECT_NEAR(k.volume, 4.f / 3.f * static_cast<float>(kPi), 1e-6f);
  }
  // a NaN distance counts as apart: nothing overlaps, nothing is NaN but the offsets it feeds
  EXPECT_EQ(sphere_overlap(std::numeric_limits<float>::quiet_NaN(), 1.f, 1.f).volume, 0.f);
  EXPECT_EQ(sphere_overlap(std::numeric_limits<float>::quiet_NaN(), 1.f, 1.f).area, 0.f);
}

}  // namespace
}  // namespace uh
