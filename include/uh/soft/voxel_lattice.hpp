#pragma once

#include <Eigen/Core>

#include <functional>
#include <vector>

#include "uh/core/result.hpp"
#include "uh/soft/tet_mesh.hpp"

namespace uh::soft {

/// Whether a point [m], in the object's frame, is inside the object (a closed mesh's inside test).
using InsidePredicate = std::function<bool(const Eigen::Vector3d&)>;

/// What to mesh: an axis-aligned region and about how many tetrahedra to fill it with.
struct LatticeOptions {
  Eigen::Vector3d min{0.0, 0.0, 0.0};  ///< lower corner of the region [m], object frame
  Eigen::Vector3d max{1.0, 1.0, 1.0};  ///< upper corner [m]; above `min` on every axis
  int target_tetrahedra = 5000;        ///< about this many elements (six per kept cell), >= 6
  /// Points [m] whose cells are kept too, whatever the inside test says of the cell's centre (the
  /// centres of a packing's spheres, so that each lies in a tetrahedron); those outside the
  /// region are ignored.
  std::vector<Eigen::Vector3d> cover{};
};

/// A voxel lattice of tetrahedra over the region: the region is cut into near-cubic cells, a cell
/// whose centre is inside is kept and split into six tetrahedra along its main diagonal (Kuhn's
/// split, the same in every cell, so neighbouring cells share faces: the mesh is conforming); so is
/// a cell holding one of the `cover` points. The
/// cell size is tuned so the kept cells give about `target_tetrahedra`. Fails (kInvalid) on an
/// empty region or target, and (kMesh) when no cell centre is inside.
Result<TetMesh> build_voxel_lattice(const InsidePredicate& inside, const LatticeOptions& options);

/// The lattice of a whole box (every cell kept), `cells` cells along each axis.
Result<TetMesh> build_box_lattice(const Eigen::Vector3d& min, const Eigen::Vector3d& max,
                                  const Eigen::Vector3i& cells);

}  // namespace uh::soft
