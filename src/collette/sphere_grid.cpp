#include "sphere_grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace uh::collette::detail {

SphereGrid::SphereGrid(const Vec3& lo, const Vec3& hi, double cell) : lo_(lo), cell_(cell) {
  const Vec3 ext = hi - lo;
  n_[0] = std::max<std::int64_t>(1, static_cast<std::int64_t>(std::ceil(ext.x / cell)));
  n_[1] = std::max<std::int64_t>(1, static_cast<std::int64_t>(std::ceil(ext.y / cell)));
  n_[2] = std::max<std::int64_t>(1, static_cast<std::int64_t>(std::ceil(ext.z / cell)));
  cells_.resize(static_cast<std::size_t>(n_[0] * n_[1] * n_[2]));
}

std::int64_t SphereGrid::clamp_cell(double v, int axis) const {
  const double o = axis == 0 ? lo_.x : (axis == 1 ? lo_.y : lo_.z);
  const double c = std::floor((v - o) / cell_);
  if (!(c > 0.0)) return 0;
  return std::min<std::int64_t>(n_[axis] - 1, static_cast<std::int64_t>(c));
}

void SphereGrid::insert(const Sphere& s, std::int32_t id) {
  if (static_cast<std::size_t>(id) >= spheres_.size()) spheres_.resize(static_cast<std::size_t>(id) + 1);
  spheres_[static_cast<std::size_t>(id)] = s;
  const double r = static_cast<double>(s.radius);
  const Vec3 c{static_cast<double>(s.x), static_cast<double>(s.y), static_cast<double>(s.z)};
  const std::int64_t i0 = clamp_cell(c.x - r, 0), i1 = clamp_cell(c.x + r, 0);
  const std::int64_t j0 = clamp_cell(c.y - r, 1), j1 = clamp_cell(c.y + r, 1);
  const std::int64_t k0 = clamp_cell(c.z - r, 2), k1 = clamp_cell(c.z + r, 2);
  for (std::int64_t k = k0; k <= k1; ++k) {
    for (std::int64_t j = j0; j <= j1; ++j) {
      for (std::int64_t i = i0; i <= i1; ++i) cells_[static_cast<std::size_t>(i + n_[0] * (j + n_[1] * k))].push_back(id);
    }
  }
}

double SphereGrid::free_radius(const Vec3& p, double reach, std::int32_t* nearest) const {
  double best = reach;
  std::int32_t best_id = -1;
  const std::int64_t i0 = clamp_cell(p.x - reach, 0), i1 = clamp_cell(p.x + reach, 0);
  const std::int64_t j0 = clamp_cell(p.y - reach, 1), j1 = clamp_cell(p.y + reach, 1);
  const std::int64_t k0 = clamp_cell(p.z - reach, 2), k1 = clamp_cell(p.z + reach, 2);
  for (std::int64_t k = k0; k <= k1; ++k) {
    for (std::int64_t j = j0; j <= j1; ++j) {
      for (std::int64_t i = i0; i <= i1; ++i) {
        for (const std::int32_t id : cell(i, j, k)) {
          const Sphere& s = spheres_[static_cast<std::size_t>(id)];
          const Vec3 c{static_cast<double>(s.x), static_cast<double>(s.y), static_cast<double>(s.z)};
          const double d = norm(p - c) - static_cast<double>(s.radius);
          if (d < best || (d == best && best_id >= 0 && id < best_id)) {
            best = d;
            best_id = id;
          }
        }
      }
    }
  }
  if (nearest != nullptr) *nearest = best_id;
  return best;
}

double SphereGrid::distance_to_union(const Vec3& p) const {
  if (spheres_.empty()) return std::numeric_limits<double>::infinity();
  const std::int64_t ci = clamp_cell(p.x, 0), cj = clamp_cell(p.y, 1), ck = clamp_cell(p.z, 2);
  // distance from p to the outside of its own (clamped) cell: a ring k further out is at least
  // k cells + this away (p may lie outside the grid, then it is 0)
  double best = std::numeric_limits<double>::infinity();
  const std::int64_t max_ring = std::max({n_[0], n_[1], n_[2]});
  for (std::int64_t ring = 0; ring <= max_ring; ++ring) {
    for (std::int64_t k = ck - ring; k <= ck + ring; ++k) {
      if (k < 0 || k >= n_[2]) continue;
      for (std::int64_t j = cj - ring; j <= cj + ring; ++j) {
        if (j < 0 || j >= n_[1]) continue;
        const bool edge_jk = (k == ck - ring || k == ck + ring || j == cj - ring || j == cj + ring);
        for (std::int64_t i = ci - ring; i <= ci + ring; ++i) {
          if (i < 0 || i >= n_[0]) continue;
          if (!edge_jk && i != ci - ring && i != ci + ring) continue;  // only the shell of this ring
          for (const std::int32_t id : cell(i, j, k)) {
            const Sphere& s = spheres_[static_cast<std::size_t>(id)];
            const Vec3 c{static_cast<double>(s.x), static_cast<double>(s.y), static_cast<double>(s.z)};
            best = std::min(best, norm(p - c) - static_cast<double>(s.radius));
          }
        }
      }
    }
    if (best <= static_cast<double>(ring) * cell_) break;
  }
  return std::max(best, 0.0);
}

}  // namespace uh::collette::detail
