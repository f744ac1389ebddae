#include "uh/core/math.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace uh {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

TEST(ClampNorm, LeavesShortVectorsAlone) {
  Vec3 v{0.3, -0.4, 0.0};
  EXPECT_FALSE(clamp_norm(v, 1.0));
  EXPECT_EQ(v, (Vec3{0.3, -0.4, 0.0}));
  Vec3 exact{3.0, 4.0, 0.0};
  EXPECT_FALSE(clamp_norm(exact, 5.0));
  Vec3 zero{};
  EXPECT_FALSE(clamp_norm(zero, 0.0));
  EXPECT_FALSE(clamp_norm(zero, -1.0));
  EXPECT_EQ(zero, Vec3{});
}

TEST(ClampNorm, ScalesLongVectorsToTheLimitKeepingTheirDirection) {
  Vec3 v{3.0, 4.0, 12.0};  // length 13
  EXPECT_TRUE(clamp_norm(v, 2.6));
  EXPECT_NEAR(v.x, 0.6, 1e-15);
  EXPECT_NEAR(v.y, 0.8, 1e-15);
  EXPECT_NEAR(v.z, 2.4, 1e-15);
  EXPECT_LE(norm(v), 2.6 * (1 + 1e-15));
}

TEST(ClampNorm, ZeroOrInvalidLimitGivesZero) {
  for (const double limit : {0.0, -1.0, kNaN}) {
    Vec3 v{1.0, 0.0, 0.0};
    EXPECT_TRUE(clamp_norm(v, limit)) << limit;
    EXPECT_EQ(v, Vec3{}) << limit;
  }
}

TEST(ClampNorm, NonFiniteVectorsBecomeZeroEvenUnderAnInfiniteLimit) {
  for (const Vec3 bad : {Vec3{kNaN, 0, 0}, Vec3{0, kInf, 0}, Vec3{0, 0, -kInf}}) {
    for (const double limit : {1.0, kInf}) {
      Vec3 v = bad;
      EXPECT_TRUE(clamp_norm(v, limit));
      EXPECT_EQ(v, Vec3{});
    }
  }
}

TEST(ClampNorm, HugeAndTinyVectorsKeepTheirDirection) {
  // the plain length of these overflows or underflows; the direction must survive either way
  Vec3 huge{3e300, -4e300, 0.0};
  EXPECT_TRUE(clamp_norm(huge, 5.0));
  EXPECT_NEAR(huge.x, 3.0, 1e-14);
  EXPECT_NEAR(huge.y, -4.0, 1e-14);
  Vec3 tiny{3e-320, 4e-320, 0.0};
  EXPECT_TRUE(clamp_norm(tiny, 1e-321));
  EXPECT_GT(tiny.x, 0.0);
  EXPECT_LE(std::hypot(tiny.x, tiny.y), 1e-321 * 1.01);
}

// Rodrigues' formula written out, independent of rotation_matrix(): R = I + sin(a) K + (1 - cos(a)) K^2
Mat3 rodrigues(Vec3 axis, double angle) {
  const Vec3 u = normalized(axis);
  const double k[3][3] = {{0, -u.z, u.y}, {u.z, 0, -u.x}, {-u.y, u.x, 0}};
  Mat3 r;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      double k2 = 0.0;
      for (int l = 0; l < 3; ++l) k2 += k[i][l] * k[l][j];
      r.m[i][j] = (i == j ? 1.0 : 0.0) + std::sin(angle) * k[i][j] + (1.0 - std::cos(angle)) * k2;
    }
  }
  return r;
}

TEST(QuatFromRotationMatrix, RotatesEveryBasisVectorOntoTheMatrixColumn) {
  const Vec3 axes[] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 2, -3}, {-0.3, 0.1, 0.9}};
  // angles include 180 degrees and its neighbours, where the trace-based formula alone fails
  const double angles[] = {0.0, 0.3, -1.2, 2.5, kPi - 1e-9, kPi, -kPi + 1e-6, 3.0};
  for (const Vec3& axis : axes) {
    for (double angle : angles) {
      const Mat3 r = rodrigues(axis, angle);
      const Quat q = quat_from_rotation_matrix(r);
      EXPECT_NEAR(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z, 1.0, 1e-12);
      EXPECT_GE(q.w, 0.0);
      const Vec3 basis[] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
      for (int j = 0; j < 3; ++j) {
        const Vec3 v = rotate(q, basis[j]);
        EXPECT_NEAR(v.x, r.m[0][j], 1e-9)
            << "axis " << axis.x << "," << axis.y << "," << axis.z << " angle " << angle;
        EXPECT_NEAR(v.y, r.m[1][j], 1e-9);
        EXPECT_NEAR(v.z, r.m[2][j], 1e-9);
      }
    }
  }
}

}  // namespace
}  // namespace uh
