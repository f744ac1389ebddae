#pragma once
/// \file
/// Small value types for 3D geometry: Vec3, Quat and Pose.
///
/// Plain aggregates (trivially copyable, no invariants beyond those documented) so that they can
/// cross threads through the handoff primitives and sit inside fixed-capacity result structs.
/// Units are SI unless a name says otherwise. Every function here is real-time safe.

#include <algorithm>
#include <cmath>

namespace uh {

/// A 3D vector of doubles: a point, a direction or a displacement (the name of the variable
/// holding it says which, and in which frame).
struct Vec3 {
  double x = 0.0;
  double y = 0.0;
  double z = 0.0;

  constexpr Vec3& operator+=(const Vec3& o) { x += o.x; y += o.y; z += o.z; return *this; }
  constexpr Vec3& operator-=(const Vec3& o) { x -= o.x; y -= o.y; z -= o.z; return *this; }
  constexpr Vec3& operator*=(double s) { x *= s; y *= s; z *= s; return *this; }
  friend constexpr Vec3 operator+(Vec3 a, const Vec3& b) { return a += b; }
  friend constexpr Vec3 operator-(Vec3 a, const Vec3& b) { return a -= b; }
  friend constexpr Vec3 operator-(const Vec3& a) { return {-a.x, -a.y, -a.z}; }
  friend constexpr Vec3 operator*(Vec3 a, double s) { return a *= s; }
  friend constexpr Vec3 operator*(double s, Vec3 a) { return a *= s; }
  friend constexpr Vec3 operator/(const Vec3& a, double s) { return {a.x / s, a.y / s, a.z / s}; }
  friend constexpr bool operator==(const Vec3&, const Vec3&) = default;
};

constexpr double dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
constexpr Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
constexpr double squared_norm(const Vec3& a) { return dot(a, a); }
inline double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }
/// Unit vector along a; the zero vector when |a| is zero or not finite.
inline Vec3 normalized(const Vec3& a) {
  const double n = norm(a);
  return (n > 0.0 && std::isfinite(n)) ? a / n : Vec3{};
}
inline bool is_finite(const Vec3& a) { return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z); }
/// Scales `v` down to length `limit` if it is longer, keeping its direction; returns whether it
/// changed `v`. A vector that is not finite, and any non-zero vector under a limit that is not
/// positive (or NaN), become zero: the result is always finite and no longer than `limit`.
/// The one norm clamp of the project (tool, safety and device limits all use it).
inline bool clamp_norm(Vec3& v, double limit) {
  if (!is_finite(v)) {
    v = {};
    return true;
  }
  // the length through the largest component, so that 1e200-sized vectors keep their direction
  const double m = std::fmax(std::fabs(v.x), std::fmax(std::fabs(v.y), std::fabs(v.z)));
  if (m == 0.0) return false;
  const Vec3 u = v / m;
  const double n_u = norm(u);  // in [1, sqrt(3)]
  if (m * n_u <= limit) return false;
  v = limit > 0.0 ? u * (limit / n_u) : Vec3{};
  return true;
}

/// A rotation as a unit quaternion, w first (the order used by scene files and the CLI).
struct Quat {
  double w = 1.0;
  double x = 0.0;
  double y = 0.0;
  double z = 0.0;

  friend constexpr bool operator==(const Quat&, const Quat&) = default;
};

/// Hamilton product: (a * b) rotates by b first, then by a.
constexpr Quat operator*(const Quat& a, const Quat& b) {
  return {a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z,
          a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
          a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
          a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
}
constexpr Quat conjugate(const Quat& q) { return {q.w, -q.x, -q.y, -q.z}; }
/// The unit quaternion along q; identity when q is zero or not finite.
inline Quat normalized(const Quat& q) {
  const double n = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
  if (!(n > 0.0) || !std::isfinite(n)) return {};
  return {q.w / n, q.x / n, q.y / n, q.z / n};
}
/// Rotation of `angle` radians about the unit vector `axis` (right-handed).
inline Quat quat_from_axis_angle(const Vec3& axis, double angle) {
  const Vec3 u = normalized(axis);
  const double s = std::sin(0.5 * angle);
  return {std::cos(0.5 * angle), u.x * s, u.y * s, u.z * s};
}
/// Rotates v by the unit quaternion q.
constexpr Vec3 rotate(const Quat& q, const Vec3& v) {
  // v' = v + 2 w (u x v) + 2 u x (u x v), u = (x, y, z): cheaper than building a matrix
  const Vec3 u{q.x, q.y, q.z};
  const Vec3 t = 2.0 * cross(u, v);
  return v + q.w * t + cross(u, t);
}

/// A rigid transform: first rotate, then translate. `Pose a_from_b` maps points given in frame b
/// to frame a: p_a = a_from_b.rotation * p_b + a_from_b.position.
struct Pose {
  Quat rotation{};
  Vec3 position{};

  friend constexpr bool operator==(const Pose&, const Pose&) = default;
};

constexpr Vec3 transform_point(const Pose& a_from_b, const Vec3& p_b) {
  return rotate(a_from_b.rotation, p_b) + a_from_b.position;
}
constexpr Vec3 transform_vector(const Pose& a_from_b, const Vec3& v_b) { return rotate(a_from_b.rotation, v_b); }
/// b_from_a given a_from_b.
constexpr Pose inverse(const Pose& a_from_b) {
  const Quat r = conjugate(a_from_b.rotation);
  return {r, -rotate(r, a_from_b.position)};
}
/// a_from_c = a_from_b * b_from_c.
constexpr Pose operator*(const Pose& a_from_b, const Pose& b_from_c) {
  return {a_from_b.rotation * b_from_c.rotation, transform_point(a_from_b, b_from_c.position)};
}

/// Row-major 3x3 rotation matrix of the unit quaternion q.
struct Mat3 {
  double m[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
};
constexpr Mat3 rotation_matrix(const Quat& q) {
  const double xx = q.x * q.x, yy = q.y * q.y, zz = q.z * q.z;
  const double xy = q.x * q.y, xz = q.x * q.z, yz = q.y * q.z;
  const double wx = q.w * q.x, wy = q.w * q.y, wz = q.w * q.z;
  return {{{1 - 2 * (yy + zz), 2 * (xy - wz), 2 * (xz + wy)},
           {2 * (xy + wz), 1 - 2 * (xx + zz), 2 * (yz - wx)},
           {2 * (xz - wy), 2 * (yz + wx), 1 - 2 * (xx + yy)}}};
}
/// The unit quaternion (w >= 0) of the row-major rotation matrix `r` (the inverse of
/// rotation_matrix). Built from the largest of the four diagonal combinations (Shepperd), so it
/// stays accurate near 180 degrees; a matrix that is not a rotation gives the nearest unit
/// quaternion of that estimate.
inline Quat quat_from_rotation_matrix(const Mat3& r) {
  const auto& m = r.m;
  const double trace = m[0][0] + m[1][1] + m[2][2];
  Quat q;
  if (trace >= m[0][0] && trace >= m[1][1] && trace >= m[2][2]) {
    const double s = 2.0 * std::sqrt(std::max(0.0, 1.0 + trace));  // 4 w
    q = {0.25 * s, (m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s};
  } else if (m[0][0] >= m[1][1] && m[0][0] >= m[2][2]) {
    const double s = 2.0 * std::sqrt(std::max(0.0, 1.0 + m[0][0] - m[1][1] - m[2][2]));  // 4 x
    q = {(m[2][1] - m[1][2]) / s, 0.25 * s, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s};
  } else if (m[1][1] >= m[2][2]) {
    const double s = 2.0 * std::sqrt(std::max(0.0, 1.0 - m[0][0] + m[1][1] - m[2][2]));  // 4 y
    q = {(m[0][2] - m[2][0]) / s, (m[0][1] + m[1][0]) / s, 0.25 * s, (m[1][2] + m[2][1]) / s};
  } else {
    const double s = 2.0 * std::sqrt(std::max(0.0, 1.0 - m[0][0] - m[1][1] + m[2][2]));  // 4 z
    q = {(m[1][0] - m[0][1]) / s, (m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, 0.25 * s};
  }
  if (q.w < 0.0) q = {-q.w, -q.x, -q.y, -q.z};
  return normalized(q);
}

inline constexpr double kPi = 3.14159265358979323846;

}  // namespace uh
