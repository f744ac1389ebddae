#include "uh/soft/voxel_lattice.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

namespace uh::soft {
namespace {

// the six tetrahedra of Kuhn's split: one per order in which a path from corner 000 to corner 111
// steps along the axes; every cell uses the same diagonal, so shared faces are cut the same way
constexpr int kAxisOrders[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};

struct Grid {
  Eigen::Vector3d min;
  Eigen::Vector3d cell_size;
  Eigen::Vector3i cells;

  Eigen::Vector3d corner(const Eigen::Vector3i& index) const {
    return min + index.cast<double>().cwiseProduct(cell_size);
  }
  std::size_t node_slot(const Eigen::Vector3i& index) const {
    const auto nx = static_cast<std::size_t>(cells.x() + 1);
    const auto ny = static_cast<std::size_t>(cells.y() + 1);
    return static_cast<std::size_t>(index.x()) +
           nx * (static_cast<std::size_t>(index.y()) + ny * static_cast<std::size_t>(index.z()));
  }
};

Grid make_grid(const Eigen::Vector3d& min, const Eigen::Vector3d& max, double edge) {
  const Eigen::Vector3d extent = max - min;
  Eigen::Vector3i cells;
  for (int axis = 0; axis < 3; ++axis) {
    cells[axis] = std::max(1, static_cast<int>(std::lround(extent[axis] / edge)));
  }
  return Grid{min, extent.cwiseQuotient(cells.cast<double>()), cells};
}

// the cells holding a cover point, one flag per cell (x fastest)
std::vector<char> covered_cells(const Grid& grid, const std::vector<Eigen::Vector3d>& cover) {
  const auto count = static_cast<std::size_t>(grid.cells.prod());
  std::vector<char> covered(cover.empty() ? 0 : count, 0);
  for (const Eigen::Vector3d& p : cover) {
    const Eigen::Vector3d at = (p - grid.min).cwiseQuotient(grid.cell_size);
    if (!at.allFinite() || (at.array() < 0.0).any() || (at.array() > grid.cells.cast<double>().array()).any()) continue;
    const Eigen::Vector3i cell = at.cast<int>().cwiseMin(grid.cells - Eigen::Vector3i::Ones());
    covered[static_cast<std::size_t>(cell.x() + grid.cells.x() * (cell.y() + grid.cells.y() * cell.z()))] = 1;
  }
  return covered;
}

template <typename Visit>
void for_each_kept_cell(const Grid& grid, const InsidePredicate& inside, const std::vector<Eigen::Vector3d>& cover,
                        Visit&& visit) {
  const std::vector<char> covered = covered_cells(grid, cover);
  std::size_t index = 0;
  for (int z = 0; z < grid.cells.z(); ++z) {
    for (int y = 0; y < grid.cells.y(); ++y) {
      for (int x = 0; x < grid.cells.x(); ++x, ++index) {
        const Eigen::Vector3i cell(x, y, z);
        if ((!covered.empty() && covered[index]) || inside(grid.corner(cell) + 0.5 * grid.cell_size)) visit(cell);
      }
    }
  }
}

std::size_t count_kept_cells(const Grid& grid, const InsidePredicate& inside, const std::vector<Eigen::Vector3d>& cover) {
  std::size_t kept = 0;
  for_each_kept_cell(grid, inside, cover, [&](const Eigen::Vector3i&) { ++kept; });
  return kept;
}

TetMesh mesh_grid(const Grid& grid, const InsidePredicate& inside, const std::vector<Eigen::Vector3d>& cover = {}) {
  TetMesh mesh;
  const std::size_t slots = grid.node_slot(grid.cells) + 1;
  std::vector<std::int32_t> node_of_slot(slots, -1);
  const auto node = [&](const Eigen::Vector3i& index) {
    std::int32_t& id = node_of_slot[grid.node_slot(index)];
    if (id < 0) {
      id = static_cast<std::int32_t>(mesh.nodes.size());
      mesh.nodes.push_back(grid.corner(index));
    }
    return id;
  };
  for_each_kept_cell(grid, inside, cover, [&](const Eigen::Vector3i& cell) {
    for (const auto& order : kAxisOrders) {
      std::array<std::int32_t, 4> tet{};
      Eigen::Vector3i corner = cell;
      tet[0] = node(corner);
      for (int step = 0; step < 3; ++step) {
        corner[order[step]] += 1;
        tet[static_cast<std::size_t>(step) + 1] = node(corner);
      }
      const auto at = [&](int i) -> const Eigen::Vector3d& {
        return mesh.nodes[static_cast<std::size_t>(tet[static_cast<std::size_t>(i)])];
      };
      if (tet_volume(at(0), at(1), at(2), at(3)) < 0.0) std::swap(tet[2], tet[3]);
      mesh.tets.push_back(tet);
    }
  });
  return mesh;
}

Status check_region(const Eigen::Vector3d& min, const Eigen::Vector3d& max) {
  if (!min.allFinite() || !max.allFinite() || !(max.array() > min.array()).all()) {
    return Error{"soft::voxel lattice: the region's max corner must be finite and above its min corner on every axis",
                 ErrorKind::kInvalid};
  }
  return Ok{};
}

}  // namespace

Result<TetMesh> build_voxel_lattice(const InsidePredicate& inside, const LatticeOptions& options) {
  if (auto region = check_region(options.min, options.max); !region) return region.error();
  if (options.target_tetrahedra < 6) {
    return Error{"soft::build_voxel_lattice: target_tetrahedra is " + std::to_string(options.target_tetrahedra) +
                     "; expected at least 6 (one cell)",
                 ErrorKind::kInvalid};
  }
  const double target_cells = options.target_tetrahedra / 6.0;
  const Eigen::Vector3d extent = options.max - options.min;
  // first guess: the whole region is inside; then scale the edge by the kept fraction
  double edge = std::cbrt(extent.prod() / target_cells);
  Grid grid = make_grid(options.min, options.max, edge);
  for (int pass = 0; pass < 4; ++pass) {
    const auto kept = static_cast<double>(count_kept_cells(grid, inside, options.cover));
    if (kept == 0.0) break;
    if (std::abs(kept / target_cells - 1.0) < 0.1) break;
    edge *= std::cbrt(kept / target_cells);
    grid = make_grid(options.min, options.max, edge);
  }
  TetMesh mesh = mesh_grid(grid, inside, options.cover);
  if (mesh.tets.empty()) {
    return Error{"soft::build_voxel_lattice: no lattice cell centre is inside the object (is the region its bounds?)",
                 ErrorKind::kMesh};
  }
  return mesh;
}

Result<TetMesh> build_box_lattice(const Eigen::Vector3d& min, const Eigen::Vector3d& max,
                                  const Eigen::Vector3i& cells) {
  if (auto region = check_region(min, max); !region) return region.error();
  if (!(cells.array() > 0).all()) {
    return Error{"soft::build_box_lattice: every axis needs at least one cell", ErrorKind::kInvalid};
  }
  const Grid grid{min, (max - min).cwiseQuotient(cells.cast<double>()), cells};
  return mesh_grid(grid, [](const Eigen::Vector3d&) { return true; });
}

}  // namespace uh::soft
