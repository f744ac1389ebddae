#include "uh/forcecomp/surface_stage.hpp"

#include <algorithm>
#include <cmath>

namespace uh::forcecomp {

SurfaceStage::SurfaceStage(const ContactMaterial& material, const SurfaceStageOptions& options)
    : material_(material), options_(options) {}

void SurfaceStage::reset() {
  touching_ = false;
  sticking_ = true;
  last_texture_force_ = {};
}

void SurfaceStage::shift_contact_point(const Vec3& delta_world, const Pose& world_from_object) {
  if (!touching_) return;
  stick_point_object_ += rotate(conjugate(world_from_object.rotation), delta_world);
  last_point_world_ += delta_world;
}

SurfaceResult SurfaceStage::apply(const Wrench& penalty, const ContactGeometry& contact,
                                  const Vec3& tool_center_of_mass_world) {
  SurfaceResult out;
  out.wrench = penalty;
  if (!active()) return out;
  const Vec3& p = contact.point_world;
  const Vec3 n = normalized(contact.normal_world);
  const double normal_force = dot(penalty.force, n);
  // the texture force held over the last period, times the contact point's motion since: its work
  // on the hand (exact for a zero-order hold)
  const Vec3 motion = touching_ ? p - last_point_world_ : Vec3{};
  const double work = dot(last_texture_force_, motion);
  if (std::isfinite(work)) texture_work_j_ += work;
  if (!(normal_force > 0.0) || !std::isfinite(normal_force) || !is_finite(p)) {
    reset();  // no contact: the stick point is placed anew at the next touch
    return out;
  }
  out.normal_force_n = normal_force;

  // texture: the heights read as a change of the contact's depth, h / depth of the normal force
  Vec3 texture_force{};
  if (material_.has_texture()) {
    const double h =
        texture_height(material_.object_texture, transform_point(inverse(contact.world_from_object), p)) +
        texture_height(material_.tool_texture, transform_point(inverse(contact.world_from_tool), p));
    const double depth = std::max(contact.depth_m, options_.min_depth_m);
    const double share = std::clamp(h / depth, -options_.max_texture_share, options_.max_texture_share);
    texture_force = (normal_force * share) * n;
    // passivity controller: the texture may do positive work (with the last tick's motion as the
    // guess of this one's) only out of what it has taken out of the hand so far; beyond that
    // credit its force is scaled down, to zero when there is none
    const double expected = dot(texture_force, motion);
    const double credit = -texture_work_j_;
    if (expected > 0.0 && expected > credit) {
      texture_force *= credit > 0.0 ? credit / expected : 0.0;
      ++texture_drops_;
    }
    if (!is_finite(texture_force)) texture_force = {};
  }
  const double pressing = normal_force + dot(texture_force, n);

  // friction: a spring to the stick point, limited by the friction cone
  Vec3 friction_force{};
  if (material_.has_friction()) {
    const Pose object_from_world = inverse(contact.world_from_object);
    const Vec3 p_object = transform_point(object_from_world, p);
    const Vec3 n_object = rotate(object_from_world.rotation, n);
    if (!touching_) {
      stick_point_object_ = p_object;
      sticking_ = true;
    }
    const Vec3 offset = p_object - stick_point_object_;
    Vec3 tangential = offset - dot(offset, n_object) * n_object;
    const double stretch = norm(tangential);
    const double k = options_.stick_stiffness;
    const double pull = k * stretch;
    if (sticking_ && pull > material_.friction_static * pressing) {
      sticking_ = false;  // breakaway
    } else if (!sticking_ && pull <= material_.friction_dynamic * pressing) {
      sticking_ = true;  // the spring relaxed inside the sliding cone: stuck again
    }
    if (!sticking_) {
      const double allowed = material_.friction_dynamic * pressing / k;
      if (stretch > allowed) {
        // drag the stick point towards the tool until the spring pulls with mu_d N: only dissipates
        const Vec3 kept = tangential * (allowed / stretch);
        stick_point_object_ += tangential - kept;
        tangential = kept;
      }
    }
    friction_force = rotate(contact.world_from_object.rotation, -k * tangential);
    if (!is_finite(friction_force)) friction_force = {};
    out.sliding = !sticking_;
  }

  out.added.force = texture_force + friction_force;
  if (options_.mode == ForceMode::k6Dof) out.added.torque = cross(p - tool_center_of_mass_world, out.added.force);
  out.wrench.force += out.added.force;
  out.wrench.torque += out.added.torque;
  out.friction_force_world = friction_force;
  out.texture_force_world = texture_force;
  touching_ = true;
  last_point_world_ = p;
  last_texture_force_ = texture_force;
  return out;
}

}  // namespace uh::forcecomp
