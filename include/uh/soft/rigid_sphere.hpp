#pragma once

#include <Eigen/Core>

#include <vector>

#include "uh/soft/corotational_fem.hpp"

namespace uh::soft {

/// A rigid sphere pressing a soft body, frictionless, as a stiff penalty on the body's nodes: a node
/// at depth d inside the sphere is pushed out along the sphere's normal with the force k d (no
/// tangential force). The body's equilibrium with these forces (CorotationalFem::solve_static with
/// `contacts()`) leaves each pressed node inside by its force over k: a stiffness far above the
/// elements' (E times the cell edge) makes that a small part of the indentation.
struct RigidSphere {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  ///< [m], object frame
  double radius_m = 0.01;                            ///< > 0
  double penalty_n_per_m = 1.0e3;                    ///< k [N/m] per node, > 0

  /// The contact model: the pressed nodes at the given positions, with their force and the
  /// penalty's stiffness along the normal, k n n^T (the turning of the normal as a node slides is
  /// left out of the stiffness: it slows the iterations a little, it does not change where they end).
  ContactModel contacts() const;

  /// The force [N] the body puts on the sphere at the node positions `positions` [m]: minus the sum
  /// of the contact forces on the nodes.
  Eigen::Vector3d force_on_sphere(const std::vector<Eigen::Vector3d>& positions) const;
};

}  // namespace uh::soft
