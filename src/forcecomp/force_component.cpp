#include "uh/forcecomp/force_component.hpp"

#include "uh/forcecomp/held_contact_set.hpp"

namespace uh::forcecomp {

BodyMotion ForceComponent::body_motion(const Pose& world_from_body, const Vec3& origin_velocity_world,
                                       const Vec3& angular_velocity_world) const {
  BodyMotion m;
  m.center_of_mass_world = transform_point(world_from_body, options_.params.center_of_mass_body);
  m.linear_velocity_world =
      origin_velocity_world + cross(angular_velocity_world, m.center_of_mass_world - world_from_body.position);
  m.angular_velocity_world = angular_velocity_world;
  return m;
}

PenaltyInput ForceComponent::penalty_input(const BodyMotion& self, const BodyMotion& other,
                                           double coverage_product) const {
  PenaltyInput in;
  in.law = options_.params.law;
  in.stiffness = options_.params.stiffness;
  in.force_scale = options_.params.force_scale;
  in.coverage_product = coverage_product;
  in.damping = options_.params.damping;
  in.damping_full_volume = options_.params.damping_full_volume;
  in.mode = options_.mode;
  in.tool_side = options_.side;
  in.tool = self;
  in.other = other;
  return in;
}

PenaltyResult ForceComponent::evaluate(std::span<const SpherePairContact> pairs, const BodyMotion& self,
                                       const BodyMotion& other, double coverage_product) const {
  return evaluate_penalty(pairs, penalty_input(self, other, coverage_product));
}

PenaltyResult ForceComponent::evaluate(const ContactFrame& frame, const BodyMotion& self,
                                       const BodyMotion& other, double coverage_product) const {
  return evaluate_penalty(frame, penalty_input(self, other, coverage_product));
}

PenaltyResult ForceComponent::evaluate(HeldContactSet& held, const Pose& world_from_a,
                                       const Pose& world_from_b, const BodyMotion& self,
                                       const BodyMotion& other, double coverage_product,
                                       const PatchSelection& selection) const {
  return held.evaluate(world_from_a, world_from_b, penalty_input(self, other, coverage_product), selection);
}

}  // namespace uh::forcecomp
