#pragma once
/// \file
/// Overlap of two solid spheres: lens volume, lens centroid and the derivative of the volume with
/// respect to the centre distance. Shared by Collette (queries) and ForceComp (per-tick
/// re-evaluation of a held pair set), so both evaluate the same formula.
///
/// For spheres (c1, r1), (c2, r2) with d = |c2 - c1|:
///  - d >= r1 + r2: no overlap;
///  - d <= |r1 - r2|: containment, the volume of the smaller sphere;
///  - otherwise the lens V = pi (r1 + r2 - d)^2 (d^2 + 2 d r1 - 3 r1^2 + 2 d r2 + 6 r1 r2 - 3 r2^2) / (12 d).
/// Real-time safe: no allocation, no branches that can throw.

#include <algorithm>
#include <cmath>

namespace uh {

/// Lens volume of two spheres whose centres are `d` apart. Units: cube of the length unit.
/// Defined for d >= 0, r1 > 0, r2 > 0.
template <typename Real>
constexpr Real lens_volume(Real d, Real r1, Real r2) {
  constexpr Real kPiR = static_cast<Real>(3.14159265358979323846);
  if (d >= r1 + r2) return Real(0);
  const Real rmin = std::min(r1, r2);
  if (d <= std::abs(r1 - r2)) return Real(4) / Real(3) * kPiR * rmin * rmin * rmin;
  const Real s = r1 + r2 - d;
  return kPiR * s * s * (d * d + Real(2) * d * r1 - Real(3) * r1 * r1 + Real(2) * d * r2 + Real(6) * r1 * r2 - Real(3) * r2 * r2) /
         (Real(12) * d);
}

/// dV/dd of lens_volume: -pi a^2 with a the radius of the intersection circle (zero when apart
/// or in containment). Its magnitude is the local stiffness of a volume penalty along the centre line.
template <typename Real>
constexpr Real lens_volume_derivative(Real d, Real r1, Real r2) {
  constexpr Real kPiR = static_cast<Real>(3.14159265358979323846);
  if (d >= r1 + r2 || d <= std::abs(r1 - r2)) return Real(0);
  const Real x = (d * d + r1 * r1 - r2 * r2) / (Real(2) * d);
  const Real a2 = std::max(Real(0), r1 * r1 - x * x);
  return -kPiR * a2;
}

/// Distance from c1 along the centre line (towards c2) to the centroid of the lens.
/// In containment the centroid is the smaller sphere's centre.
template <typename Real>
constexpr Real lens_centroid_offset(Real d, Real r1, Real r2) {
  if (d >= r1 + r2) return d * r1 / (r1 + r2);
  if (d <= std::abs(r1 - r2)) return r1 <= r2 ? Real(0) : d;
  const Real x = (d * d + r1 * r1 - r2 * r2) / (Real(2) * d);
  const Real h1 = r1 - x;        // cap of sphere 1 beyond the radical plane (towards c2)
  const Real h2 = r2 - (d - x);  // cap of sphere 2 beyond the radical plane (towards c1)
  const Real v1 = h1 * h1 * (Real(3) * r1 - h1);  // common factor pi/3 dropped from both
  const Real v2 = h2 * h2 * (Real(3) * r2 - h2);
  const Real z1 = Real(3) * (Real(2) * r1 - h1) * (Real(2) * r1 - h1) / (Real(4) * (Real(3) * r1 - h1));
  const Real z2 = d - Real(3) * (Real(2) * r2 - h2) * (Real(2) * r2 - h2) / (Real(4) * (Real(3) * r2 - h2));
  const Real total = v1 + v2;
  return total > Real(0) ? (v1 * z1 + v2 * z2) / total : x;
}

}  // namespace uh
