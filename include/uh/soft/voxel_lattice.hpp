#pragma once

#include <Eigen/Core>

#include <functional>
#include <optional>
#include <vector>

#include "uh/core/result.hpp"
#include "uh/soft/tet_mesh.hpp"

namespace uh::soft {

/// Whether a point [m], in the object's frame, is inside the object (a closed mesh's inside test).
using InsidePredicate = std::function<bool(const Eigen::Vector3d&)>;

/// Where a lattice is refined: a tensor-product grid whose cells are finest within
/// `fine_half_width_m` of `point` along each axis and grow by `growth_ratio` per cell beyond it, on
/// either side, to the region's faces (each axis's cells are scaled by one factor, close to 1, so
/// they end on the face). The point is a grid node. Neighbouring cells along an axis differ by at
/// most the ratio; a box's aspect ratio is at most its largest side over the finest cell.
struct LatticeRefinement {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  ///< [m], object frame; clamped into the region
  double fine_half_width_m = 0.0;                   ///< >= 0 [m]: cells of the finest size this far from the point
  double growth_ratio = 1.2;                        ///< in [1, 2]: size of a cell over its neighbour's nearer the point
};

/// What to mesh: an axis-aligned region and about how many tetrahedra to fill it with.
struct LatticeOptions {
  Eigen::Vector3d min{0.0, 0.0, 0.0};  ///< lower corner of the region [m], object frame
  Eigen::Vector3d max{1.0, 1.0, 1.0};  ///< upper corner [m]; above `min` on every axis
  int target_tetrahedra = 5000;        ///< about this many elements (six per kept cell), >= 6
  /// Points [m] whose cells are kept too, whatever the inside test says of the cell's centre (the
  /// centres of a packing's spheres, so that each lies in a tetrahedron); those outside the
  /// region are ignored.
  std::vector<Eigen::Vector3d> cover{};
  /// A graded grid refined near a point (the finest cell size is then tuned to the target count);
  /// none: near-cubic cells of one size.
  std::optional<LatticeRefinement> refinement{};
};

/// A voxel lattice of tetrahedra over the region: the region is cut into near-cubic cells, a cell
/// whose centre is inside is kept and split into six tetrahedra along its main diagonal (Kuhn's
/// split, the same in every cell, so neighbouring cells share faces: the mesh is conforming); so is
/// a cell holding one of the `cover` points. The
/// cell size is tuned so the kept cells give about `target_tetrahedra`. With a `refinement` the
/// cells are boxes of a graded tensor-product grid, split the same way: still conforming, and each
/// tetrahedron is a path simplex of its box (its three axis edges in a row), whose face and dihedral
/// angles are at most 90 degrees whatever the box's proportions (the maximum angle condition of
/// linear interpolation). Fails (kInvalid) on an empty region or target or a bad refinement, and
/// (kMesh) when no cell centre is inside.
Result<TetMesh> build_voxel_lattice(const InsidePredicate& inside, const LatticeOptions& options);

/// The lattice of a whole box (every cell kept), `cells` cells along each axis.
Result<TetMesh> build_box_lattice(const Eigen::Vector3d& min, const Eigen::Vector3d& max,
                                  const Eigen::Vector3i& cells);

}  // namespace uh::soft
