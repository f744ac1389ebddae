#pragma once
// Private: a uniform grid over a box in which every sphere is listed in all cells its bounding
// box touches. Answers "distance from p to the union of spheres" by searching rings of cells.

#include <cstdint>
#include <vector>

#include "uh/core/contact.hpp"
#include "uh/core/math.hpp"

namespace uh::collette::detail {

class SphereGrid {
 public:
  SphereGrid(const Vec3& lo, const Vec3& hi, double cell);

  void insert(const Sphere& s, std::int32_t id);
  /// min over spheres of |p - c| - r, looking only at spheres whose bounding box meets the
  /// cube [p - reach, p + reach]; returns `reach` if none is nearer. Sets *nearest to the index.
  double free_radius(const Vec3& p, double reach, std::int32_t* nearest) const;
  /// Same quantity without a reach limit (ring search); +inf when the grid is empty.
  double distance_to_union(const Vec3& p) const;

 private:
  std::int64_t clamp_cell(double v, int axis) const;
  const std::vector<std::int32_t>& cell(std::int64_t i, std::int64_t j, std::int64_t k) const {
    return cells_[static_cast<std::size_t>(i + n_[0] * (j + n_[1] * k))];
  }

  Vec3 lo_;
  double cell_;
  std::int64_t n_[3];
  std::vector<std::vector<std::int32_t>> cells_;
  std::vector<Sphere> spheres_;
};

}  // namespace uh::collette::detail
