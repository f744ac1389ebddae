#include "uh/forcecomp/proxy_solver.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <limits>

namespace uh::forcecomp {
namespace {

constexpr int kMaxDim = 6;
constexpr double kInfinity = std::numeric_limits<double>::infinity();
using Vec6 = std::array<double, kMaxDim>;

double dot(const Vec6& a, const Vec6& b, int n) {
  double s = 0.0;
  for (int i = 0; i < n; ++i) s += a[static_cast<std::size_t>(i)] * b[static_cast<std::size_t>(i)];
  return s;
}

// The problem in scaled coordinates y = (t, R w) (or y = t with the rotation fixed), where the
// objective is 1/2 |y - y*|^2 and constraint k reads a_k . y >= b_k.
struct Scaled {
  int dim = 6;
  double radius = 1.0;
  Vec3 fixed_rotation{};  // the rotation when it is not solved for
  void row(const ProxyConstraint& c, Vec6& a, double& b) const {
    a = {c.normal.x, c.normal.y, c.normal.z, 0.0, 0.0, 0.0};
    const Vec3 turn = cross(c.lever, c.normal);
    b = -c.gap;
    if (dim == 6) {
      a[3] = turn.x / radius;
      a[4] = turn.y / radius;
      a[5] = turn.z / radius;
    } else {
      b -= dot(turn, fixed_rotation);
    }
  }
};

// The active set: its constraint rows, their multipliers, and the Cholesky factor of their Gram
// matrix (recomputed on change: at most six rows of at most six entries).
struct ActiveSet {
  int count = 0;
  std::array<Vec6, kMaxDim> rows{};
  std::array<double, kMaxDim> multipliers{};
  std::array<std::int32_t, kMaxDim> index{};
  std::array<std::array<double, kMaxDim>, kMaxDim> chol{};

  // false when the rows are (numerically) dependent
  bool factor(int dim) {
    for (int i = 0; i < count; ++i) {
      for (int j = 0; j <= i; ++j) {
        double s = dot(rows[static_cast<std::size_t>(i)], rows[static_cast<std::size_t>(j)], dim);
        for (int k = 0; k < j; ++k) s -= chol[i][k] * chol[j][k];
        if (i == j) {
          if (s <= 1e-14) return false;
          chol[i][i] = std::sqrt(s);
        } else {
          chol[i][j] = s / chol[j][j];
        }
      }
    }
    return true;
  }
  // r = G^-1 N^T a
  std::array<double, kMaxDim> solve_gram(const Vec6& a, int dim) const {
    std::array<double, kMaxDim> r{};
    for (int i = 0; i < count; ++i) {
      double s = dot(rows[static_cast<std::size_t>(i)], a, dim);
      for (int k = 0; k < i; ++k) s -= chol[i][k] * r[static_cast<std::size_t>(k)];
      r[static_cast<std::size_t>(i)] = s / chol[i][i];
    }
    for (int i = count - 1; i >= 0; --i) {
      double s = r[static_cast<std::size_t>(i)];
      for (int k = i + 1; k < count; ++k) s -= chol[k][i] * r[static_cast<std::size_t>(k)];
      r[static_cast<std::size_t>(i)] = s / chol[i][i];
    }
    return r;
  }
  void drop(int j, int dim) {
    for (int i = j; i + 1 < count; ++i) {
      rows[static_cast<std::size_t>(i)] = rows[static_cast<std::size_t>(i + 1)];
      multipliers[static_cast<std::size_t>(i)] = multipliers[static_cast<std::size_t>(i + 1)];
      index[static_cast<std::size_t>(i)] = index[static_cast<std::size_t>(i + 1)];
    }
    --count;
    factor(dim);
  }
};

constexpr std::size_t kRowStride = 7;  // a scaled row: a (6, unit length) and its bound b

// The most violated constraint at y (by its distance: the rows have unit length), or -1.
std::int32_t most_violated(const double* rows, std::size_t count, int dim, const Vec6& y, double tolerance,
                           const ActiveSet& active) {
  std::int32_t worst = -1;
  double worst_distance = -tolerance;
  for (std::size_t k = 0; k < count; ++k) {
    const double* r = rows + k * kRowStride;
    double distance = -r[6];
    for (int d = 0; d < dim; ++d) distance += r[d] * y[static_cast<std::size_t>(d)];
    if (distance < worst_distance) {
      bool is_active = false;
      for (int i = 0; i < active.count; ++i) is_active |= active.index[static_cast<std::size_t>(i)] == static_cast<std::int32_t>(k);
      if (is_active) continue;
      worst_distance = distance;
      worst = static_cast<std::int32_t>(k);
    }
  }
  return worst;
}

}  // namespace

ProxySolver::ProxySolver(const ProxySolverOptions& options)
    : options_(options), rows_(kRowStride * static_cast<std::size_t>(std::max<std::int32_t>(options.max_constraints, 1))) {}

ProxyStep ProxySolver::solve(std::span<const ProxyConstraint> constraints, const Vec3& wanted_translation,
                             const Vec3& wanted_rotation) {
  Scaled scaled;
  scaled.dim = options_.rotate ? 6 : 3;
  scaled.radius = options_.radius_m > 0.0 ? options_.radius_m : 1.0;
  scaled.fixed_rotation = wanted_rotation;
  const int dim = scaled.dim;
  Vec6 y{wanted_translation.x, wanted_translation.y, wanted_translation.z,
         scaled.radius * wanted_rotation.x, scaled.radius * wanted_rotation.y, scaled.radius * wanted_rotation.z};
  ActiveSet active;
  ProxyStep out;
  const double tolerance = options_.tolerance_m;
  // every row scaled once, to unit length, so that a scan is a dot product per row
  assert(constraints.size() * kRowStride <= rows_.size() && "uh::forcecomp::ProxySolver::solve(): more constraints than max_constraints");
  const std::size_t count = std::min(constraints.size(), rows_.size() / kRowStride);
  for (std::size_t k = 0; k < count; ++k) {
    Vec6 a;
    double b;
    scaled.row(constraints[k], a, b);
    const double length = std::sqrt(dot(a, a, dim));
    double* r = rows_.data() + k * kRowStride;
    const double inverse = length > 0.0 ? 1.0 / length : 0.0;
    for (int d = 0; d < kMaxDim; ++d) r[d] = a[static_cast<std::size_t>(d)] * inverse;
    r[6] = length > 0.0 ? b * inverse : -kInfinity;  // a zero row is always met
  }

  std::int32_t p = most_violated(rows_.data(), count, dim, y, tolerance, active);
  double multiplier_p = 0.0;
  while (p >= 0) {
    if (out.iterations++ >= options_.max_iterations) {
      out.converged = false;
      break;
    }
    const double* row = rows_.data() + static_cast<std::size_t>(p) * kRowStride;
    Vec6 a;
    for (int d = 0; d < kMaxDim; ++d) a[static_cast<std::size_t>(d)] = row[d];
    const double b = row[6];
    // z: the part of a_p that the active rows leave free; r: how their multipliers trade against p's
    const auto r = active.solve_gram(a, dim);
    Vec6 z = a;
    for (int i = 0; i < active.count; ++i)
      for (int d = 0; d < dim; ++d)
        z[static_cast<std::size_t>(d)] -= r[static_cast<std::size_t>(i)] * active.rows[static_cast<std::size_t>(i)][static_cast<std::size_t>(d)];
    double partial = kInfinity;
    int blocking = -1;
    for (int i = 0; i < active.count; ++i) {
      const double ri = r[static_cast<std::size_t>(i)];
      if (ri > 1e-12 && active.multipliers[static_cast<std::size_t>(i)] / ri < partial) {
        partial = active.multipliers[static_cast<std::size_t>(i)] / ri;
        blocking = i;
      }
    }
    const double zz = dot(z, z, dim);
    const bool free_direction = zz > 1e-12 * dot(a, a, dim);
    if (!free_direction && blocking < 0) {
      out.converged = false;  // p contradicts the active constraints
      break;
    }
    const double full = free_direction ? -(dot(a, y, dim) - b) / zz : kInfinity;
    const double step = std::min(partial, full);
    for (int d = 0; d < dim; ++d) y[static_cast<std::size_t>(d)] += free_direction ? step * z[static_cast<std::size_t>(d)] : 0.0;
    for (int i = 0; i < active.count; ++i)
      active.multipliers[static_cast<std::size_t>(i)] -= step * r[static_cast<std::size_t>(i)];
    multiplier_p += step;
    if (step == full) {
      const int slot = active.count++;
      active.rows[static_cast<std::size_t>(slot)] = a;
      active.multipliers[static_cast<std::size_t>(slot)] = multiplier_p;
      active.index[static_cast<std::size_t>(slot)] = p;
      if (!active.factor(dim)) {  // dependent after all: leave it out
        --active.count;
        active.factor(dim);
      }
      multiplier_p = 0.0;
      p = most_violated(rows_.data(), count, dim, y, tolerance, active);
    } else {
      active.drop(blocking, dim);  // its multiplier reached zero: it no longer holds the step
    }
  }
  out.translation = {y[0], y[1], y[2]};
  out.rotation = options_.rotate ? Vec3{y[3], y[4], y[5]} / scaled.radius : wanted_rotation;
  out.active = active.count;
  for (int i = 0; i < active.count; ++i) out.active_index[i] = active.index[static_cast<std::size_t>(i)];
  return out;
}

}  // namespace uh::forcecomp
