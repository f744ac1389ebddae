#pragma once
/// \file
/// A soft object's rest model: the lattice of tetrahedra around its mesh, the nodes held in place,
/// and its Inner Sphere Tree's leaves embedded in the lattice (each in its rest tetrahedron), so
/// that the packing rides along with the simulation (docs/deformables.md, "The packing rides along").

#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "uh/core/contact.hpp"
#include "uh/core/result.hpp"
#include "uh/soft/corotational_fem.hpp"
#include "uh/soft/surface_mesh.hpp"
#include "uh/soft/tet_mesh.hpp"
#include "uh/soft/voxel_lattice.hpp"

namespace uh::soft {

/// An axis-aligned box [m], object frame, bounds included.
struct Box {
  Eigen::Vector3d min = Eigen::Vector3d::Zero();
  Eigen::Vector3d max = Eigen::Vector3d::Zero();
};

/// What a scene says of a soft object (scene's `objects[].deformable`), in this module's terms.
struct SoftBodyParams {
  ElasticMaterial material{};
  int target_tetrahedra = 0;    ///< about this many elements; 0 = default_tetrahedra() of the packing's size
  std::optional<Box> fixed{};   ///< the nodes inside are held in place; none: a free body
  SurfaceMesh surface{};        ///< the drawn surface (refine_surface), embedded too; may be empty
};

/// The lattice size chosen for an object whose packing spans `extent` [m]: cells of a tenth of
/// its longest side, six tetrahedra each, within [384, 3000] (a simulation step of a few
/// milliseconds on one core, bench/soft).
int default_tetrahedra(const Eigen::Vector3d& extent);

/// A leaf sphere in its rest tetrahedron: the barycentric weights of its centre (each >= 0,
/// summing to 1) and its rest radius [m].
struct EmbeddedSphere {
  std::int32_t tet = 0;
  Eigen::Vector4d weights = Eigen::Vector4d::Zero();
  double rest_radius = 0.0;
};

/// A vertex of the drawn surface in its tetrahedron: barycentric weights that give its rest
/// position exactly. A vertex inside a tetrahedron has weights >= 0; one outside every kept
/// tetrahedron (the lattice's staircase lies inside the mesh's faces) takes the tetrahedron with
/// the nearest centroid, its weights extrapolated (some negative, still summing to 1), so the
/// vertex moves with that element's affine motion. `tet` is kHeldVertex for a vertex in the fixed
/// box: it stays at its rest position, as the nodes there do.
struct EmbeddedVertex {
  static constexpr std::int32_t kHeldVertex = -1;
  std::int32_t tet = kHeldVertex;
  Eigen::Vector4d weights = Eigen::Vector4d::Zero();
};

/// A soft object's rest model, built once at compile: immutable, shared by the sessions.
struct SoftBodyModel {
  TetMesh mesh;
  ElasticMaterial material;
  std::vector<std::int32_t> fixed;          ///< held nodes (in the fixed box)
  std::vector<EmbeddedSphere> spheres;      ///< one per leaf of the packing, in packing order
  /// The spheres' indices ordered by their tetrahedron: deform_spheres finds each tetrahedron's
  /// stretch once for all its spheres (a face's small spheres share their element).
  std::vector<std::int32_t> spheres_by_tet;
  std::vector<Eigen::Matrix3d> rest_inverse;///< per tetrahedron: inverse of its rest edge matrix
  SurfaceMesh surface;                      ///< the drawn surface at rest (SoftBodyParams::surface)
  std::vector<EmbeddedVertex> surface_embedding;  ///< one per surface vertex
};

/// Builds the lattice over the bounds of `leaves` (the packing, metres), keeping cells whose centre
/// `inside` accepts or which hold a leaf's centre, embeds every leaf, finds the fixed nodes.
/// Fails (kInvalid) on no leaves or a fixed box holding no node, (kMesh) when a centre lies in no
/// tetrahedron. Embeds `params.surface`'s vertices (EmbeddedVertex). Setup only.
Result<SoftBodyModel> build_soft_body(const InsidePredicate& inside, std::span<const Sphere> leaves,
                                      const SoftBodyParams& params);

/// The leaves of a body whose nodes are at `positions` (one per node, object frame [m]) into `out`
/// (one per leaf): each centre at its barycentric weights in its tetrahedron, each radius its rest
/// radius times that tetrahedron's smallest principal stretch (the smallest singular value of
/// its deformation gradient, at least kMinSphereStretch: an inverted element keeps a small
/// sphere), so a compressed sphere shrinks with its element: once per tetrahedron (spheres_by_tet),
/// from the eigenvalues of F^T F in closed form. Real-time safe: no allocation.
void deform_spheres(const SoftBodyModel& body, const std::vector<Eigen::Vector3d>& positions, std::span<Sphere> out);

/// The drawn surface's vertices of a body whose nodes are at `positions`, as x, y, z floats
/// [m, object frame] into `xyz` (3 per surface vertex; a shorter span gets the first ones): each
/// vertex at its weights in its tetrahedron, a held one at its rest position. Real-time safe.
void deform_surface(const SoftBodyModel& body, const std::vector<Eigen::Vector3d>& positions, std::span<float> xyz);

/// The smallest stretch a sphere's radius is scaled by.
inline constexpr double kMinSphereStretch = 0.05;

/// Adds `force` [N] on leaf `leaf` to the nodal loads (one per node) of its tetrahedron, by its
/// barycentric weights: the loads sum to the force, and do the same virtual work for a motion
/// of the nodes as the force does at the sphere's centre. Real-time safe.
void spread_sphere_force(const SoftBodyModel& body, std::int32_t leaf, const Eigen::Vector3d& force,
                         std::vector<Eigen::Vector3d>& nodal_loads);

}  // namespace uh::soft
