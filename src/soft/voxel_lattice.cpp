#include "uh/soft/voxel_lattice.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <utility>

namespace uh::soft {
namespace {

// the six tetrahedra of Kuhn's split: one per order in which a path from corner 000 to corner 111
// steps along the axes; every cell uses the same diagonal, so shared faces are cut the same way
constexpr int kAxisOrders[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};

// one axis of the grid: its node coordinates, and the centre of each cell between them
struct Axis {
  std::vector<double> nodes;
  std::vector<double> centres;
  double uniform_size = 0.0;  // the cell size of a uniform axis, 0 when graded

  static Axis uniform(double min, double size, int cells) {
    Axis axis;
    axis.uniform_size = size;
    for (int i = 0; i <= cells; ++i) axis.nodes.push_back(min + static_cast<double>(i) * size);
    for (int i = 0; i < cells; ++i) axis.centres.push_back(axis.nodes[static_cast<std::size_t>(i)] + 0.5 * size);
    return axis;
  }
  static Axis graded(std::vector<double> nodes) {
    Axis axis;
    axis.nodes = std::move(nodes);
    for (std::size_t i = 0; i + 1 < axis.nodes.size(); ++i) axis.centres.push_back(0.5 * (axis.nodes[i] + axis.nodes[i + 1]));
    return axis;
  }
  int cells() const { return static_cast<int>(centres.size()); }
  // the cell holding x, -1 outside the axis's span
  int cell_of(double x) const {
    if (uniform_size > 0.0) {
      const double at = (x - nodes.front()) / uniform_size;
      if (!std::isfinite(at) || at < 0.0 || at > cells()) return -1;
      return std::min(static_cast<int>(at), cells() - 1);
    }
    if (!(x >= nodes.front() && x <= nodes.back())) return -1;
    const auto above = std::upper_bound(nodes.begin(), nodes.end(), x);
    return std::min(static_cast<int>(above - nodes.begin()) - 1, cells() - 1);
  }
};

struct Grid {
  std::array<Axis, 3> axes;
  Eigen::Vector3i cells;

  explicit Grid(std::array<Axis, 3> per_axis)
      : axes(std::move(per_axis)), cells(axes[0].cells(), axes[1].cells(), axes[2].cells()) {}

  Eigen::Vector3d corner(const Eigen::Vector3i& index) const {
    return {axes[0].nodes[static_cast<std::size_t>(index.x())], axes[1].nodes[static_cast<std::size_t>(index.y())],
            axes[2].nodes[static_cast<std::size_t>(index.z())]};
  }
  Eigen::Vector3d centre(const Eigen::Vector3i& cell) const {
    return {axes[0].centres[static_cast<std::size_t>(cell.x())], axes[1].centres[static_cast<std::size_t>(cell.y())],
            axes[2].centres[static_cast<std::size_t>(cell.z())]};
  }
  std::size_t node_slot(const Eigen::Vector3i& index) const {
    const auto nx = static_cast<std::size_t>(cells.x() + 1);
    const auto ny = static_cast<std::size_t>(cells.y() + 1);
    return static_cast<std::size_t>(index.x()) +
           nx * (static_cast<std::size_t>(index.y()) + ny * static_cast<std::size_t>(index.z()));
  }
};

Grid uniform_grid(const Eigen::Vector3d& min, const Eigen::Vector3d& max, const Eigen::Vector3i& cells) {
  const Eigen::Vector3d size = (max - min).cwiseQuotient(cells.cast<double>());
  return Grid({Axis::uniform(min.x(), size.x(), cells.x()), Axis::uniform(min.y(), size.y(), cells.y()),
               Axis::uniform(min.z(), size.z(), cells.z())});
}

Grid make_grid(const Eigen::Vector3d& min, const Eigen::Vector3d& max, double edge) {
  const Eigen::Vector3d extent = max - min;
  Eigen::Vector3i cells;
  for (int axis = 0; axis < 3; ++axis) {
    cells[axis] = std::max(1, static_cast<int>(std::lround(extent[axis] / edge)));
  }
  return uniform_grid(min, max, cells);
}

// The cell sizes from a point to a face `length` away: `fine` up to `fine_width`, then each `ratio`
// times the last; as many as make the sum closest to the length, all scaled by one factor to meet it.
std::vector<double> graded_sizes(double length, double fine, double fine_width, double ratio) {
  std::vector<double> sizes;
  if (length <= 0.0) return sizes;
  double sum = 0.0, size = fine;
  while (sum < length) {
    if (sum >= fine_width - 1e-9 * fine) size = sizes.empty() ? fine : std::max(fine, sizes.back() * ratio);
    if (!sizes.empty() && length - sum < sum + size - length) break;  // one fewer lands closer
    sizes.push_back(size);
    sum += size;
  }
  for (double& s : sizes) s *= length / sum;
  return sizes;
}

Axis graded_axis(double min, double max, double point, double fine, double fine_width, double ratio) {
  const double at = std::clamp(point, min, max);
  const std::vector<double> below = graded_sizes(at - min, fine, fine_width, ratio);
  const std::vector<double> above = graded_sizes(max - at, fine, fine_width, ratio);
  std::vector<double> nodes{min};
  double x = min;
  for (auto s = below.rbegin(); s != below.rend(); ++s) nodes.push_back(x += *s);
  nodes.back() = at;  // the point is a node (and the sums' rounding stays off it)
  if (below.empty()) nodes.back() = min;
  x = nodes.back();
  for (const double s : above) nodes.push_back(x += s);
  nodes.back() = max;
  return Axis::graded(std::move(nodes));
}

Grid graded_grid(const Eigen::Vector3d& min, const Eigen::Vector3d& max, const LatticeRefinement& refinement,
                 double fine) {
  std::array<Axis, 3> axes;
  for (int a = 0; a < 3; ++a) {
    axes[static_cast<std::size_t>(a)] = graded_axis(min[a], max[a], refinement.point[a], fine,
                                                    refinement.fine_half_width_m, refinement.growth_ratio);
  }
  return Grid(std::move(axes));
}

// the cells holding a cover point, one flag per cell (x fastest)
std::vector<char> covered_cells(const Grid& grid, const std::vector<Eigen::Vector3d>& cover) {
  const auto count = static_cast<std::size_t>(grid.cells.prod());
  std::vector<char> covered(cover.empty() ? 0 : count, 0);
  for (const Eigen::Vector3d& p : cover) {
    const Eigen::Vector3i cell(grid.axes[0].cell_of(p.x()), grid.axes[1].cell_of(p.y()), grid.axes[2].cell_of(p.z()));
    if ((cell.array() < 0).any()) continue;
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
        if ((!covered.empty() && covered[index]) || inside(grid.centre(cell))) visit(cell);
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

Status check_refinement(const LatticeRefinement& refinement) {
  const auto invalid = [](const std::string& what) {
    return Error{"soft::build_voxel_lattice: the refinement's " + what, ErrorKind::kInvalid};
  };
  if (!refinement.point.allFinite()) return invalid("point is not finite");
  if (!(std::isfinite(refinement.fine_half_width_m) && refinement.fine_half_width_m >= 0.0)) {
    return invalid("fine_half_width_m is " + std::to_string(refinement.fine_half_width_m) + "; expected >= 0");
  }
  if (!(refinement.growth_ratio >= 1.0 && refinement.growth_ratio <= 2.0)) {
    return invalid("growth_ratio is " + std::to_string(refinement.growth_ratio) + "; expected in [1, 2]");
  }
  return Ok{};
}

// near-cubic cells of one edge, scaled by the kept fraction: first guess, the whole region is inside
Grid uniform_grid_near_target(const InsidePredicate& inside, const LatticeOptions& options, double target_cells) {
  double edge = std::cbrt((options.max - options.min).prod() / target_cells);
  Grid grid = make_grid(options.min, options.max, edge);
  for (int pass = 0; pass < 4; ++pass) {
    const auto kept = static_cast<double>(count_kept_cells(grid, inside, options.cover));
    if (kept == 0.0) break;
    if (std::abs(kept / target_cells - 1.0) < 0.1) break;
    edge *= std::cbrt(kept / target_cells);
    grid = make_grid(options.min, options.max, edge);
  }
  return grid;
}

// the graded grid whose finest cell gives the kept count nearest the target: the count falls as
// the finest cell grows, so bisect its logarithm between one cell across the region and a size
// that keeps at least the target
Grid graded_grid_near_target(const InsidePredicate& inside, const LatticeOptions& options, double target_cells) {
  const LatticeRefinement& refinement = *options.refinement;
  const auto grid_of = [&](double fine) { return graded_grid(options.min, options.max, refinement, fine); };
  const auto kept = [&](double fine) { return static_cast<double>(count_kept_cells(grid_of(fine), inside, options.cover)); };
  // (and a grid of at most a thousand times the target cells, for an object filling little of it)
  const auto too_large = [&](double finest) { return grid_of(finest).cells.cast<double>().prod() > 1000.0 * target_cells; };
  double coarse = (options.max - options.min).maxCoeff();
  double fine = coarse;
  while (kept(fine) < target_cells && !too_large(0.5 * fine)) fine *= 0.5;
  double best = fine, best_error = std::abs(std::log(kept(fine) / target_cells));
  for (int step = 0; step < 40 && best_error > 0.02; ++step) {
    const double middle = std::sqrt(fine * coarse);
    const double count = kept(middle);
    if (count > 0.0 && std::abs(std::log(count / target_cells)) < best_error) {
      best = middle;
      best_error = std::abs(std::log(count / target_cells));
    }
    (count >= target_cells ? fine : coarse) = middle;
  }
  return grid_of(best);
}

}  // namespace

Result<TetMesh> build_voxel_lattice(const InsidePredicate& inside, const LatticeOptions& options) {
  if (auto region = check_region(options.min, options.max); !region) return region.error();
  if (options.target_tetrahedra < 6) {
    return Error{"soft::build_voxel_lattice: target_tetrahedra is " + std::to_string(options.target_tetrahedra) +
                     "; expected at least 6 (one cell)",
                 ErrorKind::kInvalid};
  }
  if (options.refinement) {
    if (auto refinement = check_refinement(*options.refinement); !refinement) return refinement.error();
  }
  const double target_cells = options.target_tetrahedra / 6.0;
  const Grid grid = options.refinement ? graded_grid_near_target(inside, options, target_cells)
                                       : uniform_grid_near_target(inside, options, target_cells);
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
  return mesh_grid(uniform_grid(min, max, cells), [](const Eigen::Vector3d&) { return true; });
}

}  // namespace uh::soft
