#pragma once
// An independent reference for the overlap of two spheres, for the brute-force checks of the
// queries and the force laws: the textbook cap decomposition (radical plane x, caps of heights
// r1 - x and r2 - (d - x), each pi h^2 (3 r - h) / 3, centroids 3 (2r - h)^2 / (4 (3r - h)) from
// their sphere's centre) evaluated in long double. It shares no code and no algebra with
// uh::sphere_overlap (include/uh/core/sphere_overlap.hpp), which tests/core/sphere_overlap_test.cpp
// checks against quadruple-precision integration; here the geometry of test scenes is never so
// degenerate that the textbook form's cancellation shows in long double.

#include <algorithm>
#include <cmath>

namespace uh::test {

struct LensReference {
  double volume = 0.0;           // [L^3]
  double area = 0.0;             // pi a^2 of the intersection disk [L^2]
  double centroid_offset = 0.0;  // from c1 along the centre line [L]
};

inline LensReference lens_reference(double d_in, double r1_in, double r2_in) {
  using Long = long double;
  const Long pi = 3.14159265358979323846264338327950288L;
  const Long d = static_cast<Long>(d_in), r1 = static_cast<Long>(r1_in), r2 = static_cast<Long>(r2_in);
  LensReference out;
  if (d >= r1 + r2) {
    out.centroid_offset = static_cast<double>(d * r1 / (r1 + r2));
    return out;
  }
  if (d <= std::fabs(r1 - r2)) {
    const Long r = std::min(r1, r2);
    out.volume = static_cast<double>(4 * pi * r * r * r / 3);
    out.centroid_offset = r1 <= r2 ? 0.0 : d_in;
    return out;
  }
  const Long x = (d * d + r1 * r1 - r2 * r2) / (2 * d);
  const Long h1 = r1 - x, h2 = r2 - (d - x);
  const Long v1 = pi * h1 * h1 * (3 * r1 - h1) / 3, v2 = pi * h2 * h2 * (3 * r2 - h2) / 3;
  const Long z1 = 3 * (2 * r1 - h1) * (2 * r1 - h1) / (4 * (3 * r1 - h1));
  const Long z2 = d - 3 * (2 * r2 - h2) * (2 * r2 - h2) / (4 * (3 * r2 - h2));
  out.volume = static_cast<double>(v1 + v2);
  out.area = static_cast<double>(pi * (r1 * r1 - x * x));
  out.centroid_offset = static_cast<double>((v1 * z1 + v2 * z2) / (v1 + v2));
  return out;
}

}  // namespace uh::test
