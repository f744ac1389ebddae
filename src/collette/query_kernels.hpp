#pragma once
// Shared inner-loop helpers of the sphere-tree queries (private to Collette).

#include <cmath>

#include "uh/core/math.hpp"

namespace uh::collette::detail {

/// b_in_a as a float 3x4 matrix: the queries transform B's node centres with it.
struct FloatTransform {
  float r[3][3];
  float t[3];

  static FloatTransform from(const Pose& p) {
    const Mat3 m = rotation_matrix(normalized(p.rotation));
    FloatTransform f{};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) f.r[i][j] = static_cast<float>(m.m[i][j]);
    f.t[0] = static_cast<float>(p.position.x);
    f.t[1] = static_cast<float>(p.position.y);
    f.t[2] = static_cast<float>(p.position.z);
    return f;
  }

  void apply(float x, float y, float z, float& ox, float& oy, float& oz) const {
    ox = r[0][0] * x + r[0][1] * y + r[0][2] * z + t[0];
    oy = r[1][0] * x + r[1][1] * y + r[1][2] * z + t[1];
    oz = r[2][0] * x + r[2][1] * y + r[2][2] * z + t[2];
  }
};

}  // namespace uh::collette::detail
