#include "uh/soft/rigid_sphere.hpp"

#include <cmath>

namespace uh::soft {
namespace {

// the contact of a node at `position`, if it is inside the sphere (at its centre the normal is
// undefined: the node is left out, which a sphere larger than a cell never meets)
bool node_contact(const RigidSphere& sphere, const Eigen::Vector3d& position, NodeContact& contact) {
  const Eigen::Vector3d out = position - sphere.centre;
  const double distance = out.norm();
  const double depth = sphere.radius_m - distance;
  if (!(depth > 0.0) || !(distance > 0.0)) return false;
  const Eigen::Vector3d normal = out / distance;
  contact.force = sphere.penalty_n_per_m * depth * normal;
  contact.stiffness = sphere.penalty_n_per_m * normal * normal.transpose();
  return true;
}

}  // namespace

ContactModel RigidSphere::contacts() const {
  return [sphere = *this](const std::vector<Eigen::Vector3d>& positions, std::vector<NodeContact>& contacts) {
    NodeContact contact;
    for (std::size_t node = 0; node < positions.size(); ++node) {
      if (!node_contact(sphere, positions[node], contact)) continue;
      contact.node = static_cast<std::int32_t>(node);
      contacts.push_back(contact);
    }
  };
}

Eigen::Vector3d RigidSphere::force_on_sphere(const std::vector<Eigen::Vector3d>& positions) const {
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  NodeContact contact;
  for (const Eigen::Vector3d& position : positions) {
    if (node_contact(*this, position, contact)) force -= contact.force;
  }
  return force;
}

}  // namespace uh::soft
