#pragma once
/// \file
/// The overlap of two solid spheres: lens volume, area and centre of the intersection disk, lens
/// centroid and dV/dd. The one lens kernel of the project: Collette's queries, ForceComp's per-tick
/// re-evaluation of held pairs and the force laws all call sphere_overlap(), so they agree.
///
/// For spheres (c1, r1), (c2, r2), d = |c2 - c1|, s = r1 + r2 - d (penetration), delta = r1 - r2:
///  - d >= r1 + r2: apart, nothing overlaps;
///  - d <= |delta|: containment, the volume of the smaller sphere (this includes d = 0, r1 = r2);
///  - otherwise a lens, the union of two caps beyond the radical plane, of heights
///    h1 = s (d - delta) / (2 d), h2 = s (d + delta) / (2 d):
///        V = pi/3 (h1^2 (3 r1 - h1) + h2^2 (3 r2 - h2))
///          = pi (r1 + r2 - d)^2 (d^2 + 2 d (r1 + r2) - 3 delta^2) / (12 d),
///    intersection disk radius a^2 = s (r1 + r2 + d) (d - delta) (d + delta) / (4 d^2), dV/dd = -pi a^2,
///    lens centroid at d V2 / (V1 + V2) from c1 (the first moments of the caps about the plane are
///    both pi a^4 / 4 and cancel).
///
/// Why these forms: the textbook expansion d^2 + 2 d r1 - 3 r1^2 + 2 d r2 + 6 r1 r2 - 3 r2^2 and the
/// cap heights r1 - x loses every digit when r1 ~ r2 and d is small (two packings of one object
/// nearly on top of each other gave more volume than the spheres hold). Here every quantity is a
/// product and quotient of positive factors that are each one subtraction of inputs, so the result
/// is as accurate as its inputs allow (backward stable: a few ulps, plus the change that moving the
/// inputs by an ulp makes). A lens volume is never above the smaller sphere's volume as this
/// kernel computes it for containment. Nothing divides by zero: the lens branch has d > |delta| >= 0.
///
/// Templated on the floating-point type (float on the query and haptic paths, double elsewhere).
/// Real-time safe: no allocation, no exceptions, no branches on NaN that could trap.

#include <algorithm>
#include <cmath>
#include <limits>

namespace uh {

/// What sphere_overlap() returns. Offsets are signed distances from c1 along the unit centre line
/// u = (c2 - c1) / d; the points c1 + offset * u are world points once c1 and u are.
template <typename Real>
struct SphereOverlap {
  Real volume = Real(0);  ///< overlap volume [L^3], >= 0
  Real area = Real(0);    ///< pi a^2, area of the intersection disk [L^2] = -dV/dd; 0 apart or in containment
  Real disk_offset = Real(0);  ///< to the centre of the intersection disk (the radical plane) [L]; may be < 0
  Real centroid_offset = Real(0);  ///< to the centroid of the overlap [L]
};

/// Overlap of spheres of radii `r1`, `r2` whose centres are `d` apart. Defined for d >= 0, r1 > 0,
/// r2 > 0. Apart: volume and area 0, both offsets at d r1 / (r1 + r2) (the point where the
/// spheres would first touch). Containment: the smaller sphere's volume, area 0, both offsets at
/// the smaller sphere's centre (0 when r1 <= r2, else d).
template <typename Real>
constexpr SphereOverlap<Real> sphere_overlap(Real d, Real r1, Real r2) {
  constexpr Real kPiR = static_cast<Real>(3.14159265358979323846264338327950288L);
  SphereOverlap<Real> o;
  const Real sum = r1 + r2;
  if (!(d < sum)) {
    o.disk_offset = o.centroid_offset = d * r1 / sum;
    return o;
  }
  const Real delta = r1 - r2;
  const Real rmin = std::min(r1, r2);
  const Real contained = Real(4) / Real(3) * kPiR * rmin * rmin * rmin;
  // centres closer than the smallest normal number count as coincident (so 0.5 / d stays finite)
  if (d <= std::abs(delta) || d < std::numeric_limits<Real>::min()) {
    o.volume = contained;
    o.disk_offset = o.centroid_offset = r1 <= r2 ? Real(0) : d;
    return o;
  }
  // lens: d > |delta| >= 0, so both shares p1, p2 lie in (0, 1] and sum to 1
  const Real s = sum - d;
  const Real half_inv_d = Real(0.5) / d;
  const Real p1 = (d - delta) * half_inv_d;           // h1 / s
  const Real p2 = (d + delta) * half_inv_d;           // h2 / s
  const Real t1 = p1 * p1 * (Real(3) * r1 - s * p1);  // cap volumes / (pi/3 s^2), each >= p^2 r > 0
  const Real t2 = p2 * p2 * (Real(3) * r2 - s * p2);
  o.volume = std::min(kPiR / Real(3) * s * s * (t1 + t2), contained);
  o.area = kPiR * s * (sum + d) * p1 * p2;
  o.disk_offset = (d * d + delta * sum) * half_inv_d;
  o.centroid_offset = d * t2 / (t1 + t2);
  return o;
}

/// The overlap volume alone (sphere_overlap(d, r1, r2).volume) [L^3].
template <typename Real>
constexpr Real lens_volume(Real d, Real r1, Real r2) {
  return sphere_overlap(d, r1, r2).volume;
}

}  // namespace uh
