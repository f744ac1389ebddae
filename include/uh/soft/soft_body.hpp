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

/// A soft object's rest model, built once at compile: immutable, shared by the sessions.
struct SoftBodyModel {
  TetMesh mesh;
  ElasticMaterial material;
  std::vector<std::int32_t> fixed;          ///< held nodes (in the fixed box)
  std::vector<EmbeddedSphere> spheres;      ///< one per leaf of the packing, in packing order
  std::vector<Eigen::Matrix3d> rest_inverse;///< per tetrahedron: inverse of its rest edge matrix
};

/// Builds the lattice over the bounds of `leaves` (the packing, metres), keeping cells whose centre
/// `inside` accepts or which hold a leaf's centre, embeds every leaf, finds the fixed nodes.
/// Fails (kInvalid) on no leaves or a fixed box holding no node, (kMesh) when a centre lies in no
/// tetrahedron. Setup only.
Result<SoftBodyModel> build_soft_body(const InsidePredicate& inside, std::span<const Sphere> leaves,
                                      const SoftBodyParams& params);

/// The leaves of a body whose nodes are at `positions` (one per node, object frame [m]) into `out`
/// (one per leaf): each centre at its barycentric weights in its tetrahedron, each radius its rest
/// radius times that tetrahedron's smallest principal stretch (the smallest singular value of
/// its deformation gradient, at least kMinSphereStretch: an inverted element keeps a small
/// sphere), so a compressed sphere shrinks with its element. Real-time safe: no allocation.
void deform_spheres(const SoftBodyModel& body, const std::vector<Eigen::Vector3d>& positions, std::span<Sphere> out);

/// The smallest stretch a sphere's radius is scaled by.
inline constexpr double kMinSphereStretch = 0.05;

/// Adds `force` [N] on leaf `leaf` to the nodal loads (one per node) of its tetrahedron, by its
/// barycentric weights: the loads sum to the force, and do the same virtual work for a motion
/// of the nodes as the force does at the sphere's centre. Real-time safe.
void spread_sphere_force(const SoftBodyModel& body, std::int32_t leaf, const Eigen::Vector3d& force,
                         std::vector<Eigen::Vector3d>& nodal_loads);

}  // namespace uh::soft
