#include "uh/forcecomp/held_contact_set.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "penalty_terms.hpp"
#include "uh/core/sphere_overlap.hpp"

namespace uh::forcecomp {

namespace {

Vec3 centre(const Sphere& s) {
  return {static_cast<double>(s.x), static_cast<double>(s.y), static_cast<double>(s.z)};
}

void store(float (&out)[3], const Vec3& v) {
  out[0] = static_cast<float>(v.x);
  out[1] = static_cast<float>(v.y);
  out[2] = static_cast<float>(v.z);
}

}  // namespace

HeldContactSet::HeldContactSet(std::int32_t reevaluate_capacity)
    : scratch_capacity_(std::max(reevaluate_capacity, 0)),
      scratch_(new SpherePairContact[static_cast<std::size_t>(std::max(reevaluate_capacity, 1))]) {
  assert(reevaluate_capacity >= 0 &&
         "uh::forcecomp::HeldContactSet::HeldContactSet(): capacity must be >= 0");
}

void HeldContactSet::hold(const ContactFrame& frame) {
  hold(frame.pairs(), frame.sequence, frame.time_s);
  // the frame knows its poses: the normals go into A's frame for the coincident-centre case
  const auto sections = frame.sections();
  a_from_world_held_ =
      conjugate(sections.empty() ? frame.world_from_a.rotation : sections.front().world_from_a.rotation);
}

void HeldContactSet::hold(const ContactFrame& frame, const ContactSection& section) {
  hold(frame.pairs().subspan(static_cast<std::size_t>(section.first_pair),
                             static_cast<std::size_t>(section.pair_count)),
       frame.sequence, frame.time_s);
  a_from_world_held_ = conjugate(section.world_from_a.rotation);
}

void HeldContactSet::hold(std::span<const SpherePairContact> pairs, std::uint64_t sequence, double time_s) {
  held_ = pairs;
  // without poses the world normal is the best guess for A's frame (exact when A is unrotated)
  a_from_world_held_ = Quat{};
  sequence_ = sequence;
  time_s_ = time_s;
}

void HeldContactSet::clear() {
  held_ = {};
  sequence_ = 0;
  time_s_ = 0.0;
}

std::span<const SpherePairContact> HeldContactSet::reevaluate(const Pose& world_from_a,
                                                              const Pose& world_from_b) {
  const std::size_t n = std::min(held_.size(), static_cast<std::size_t>(scratch_capacity_));
  dropped_pairs_ += held_.size() - n;
  for (std::size_t i = 0; i < n; ++i) {
    const SpherePairContact& in = held_[i];
    SpherePairContact& out = scratch_[i];
    out = in;
    const Vec3 ca = transform_point(world_from_a, centre(in.sphere_a_local));
    const Vec3 cb = transform_point(world_from_b, centre(in.sphere_b_local));
    const double ra = static_cast<double>(in.sphere_a_local.radius);
    const double rb = static_cast<double>(in.sphere_b_local.radius);
    const Vec3 delta = cb - ca;
    const double d = norm(delta);
    const SphereOverlap<double> o = sphere_overlap(d, ra, rb);
    // coincident centres (within float storage precision) leave the centre line undefined: keep
    // the held normal, turned with A
    const Vec3 u = d > 1e-6 * (ra + rb) ? delta / d : rotate(world_from_a.rotation, held_normal_in_a(in));
    const Vec3 centroid = ca + o.centroid_offset * u;
    out.volume = static_cast<float>(o.volume);
    out.area = static_cast<float>(o.area);
    store(out.normal_world, u);
    store(out.centroid_world, centroid);
  }
  return {scratch_.get(), n};
}

PenaltyResult HeldContactSet::evaluate(const Pose& world_from_a, const Pose& world_from_b,
                                       const PenaltyInput& input, const PatchSelection& selection) {
  // everything in A's frame: A's spheres need no transform, B's one; the sums turn back at the end
  const Pose a_from_world = inverse(world_from_a);
  const Pose a_from_b = a_from_world * world_from_b;
  // Per pair in float with the one lens kernel, as the collision query does (it is backward stable
  // in float: a few ulps), sums in double: this loop runs every haptic tick over up to tens of
  // thousands of pairs.
  const Mat3 rot = rotation_matrix(a_from_b.rotation);
  float r[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r[i][j] = static_cast<float>(rot.m[i][j]);
  const float tx = static_cast<float>(a_from_b.position.x), ty = static_cast<float>(a_from_b.position.y),
              tz = static_cast<float>(a_from_b.position.z);
  // B's sphere of a held pair in A's frame, its distance to A's sphere; false when apart
  struct Local {
    float dx, dy, dz, d2, rs;
  };
  const auto place = [&](const SpherePairContact& p, Local& l) {
    const Sphere& b = p.sphere_b_local;
    const Sphere& a = p.sphere_a_local;
    l.dx = r[0][0] * b.x + r[0][1] * b.y + r[0][2] * b.z + tx - a.x;
    l.dy = r[1][0] * b.x + r[1][1] * b.y + r[1][2] * b.z + ty - a.y;
    l.dz = r[2][0] * b.x + r[2][1] * b.y + r[2][2] * b.z + tz - a.z;
    l.d2 = l.dx * l.dx + l.dy * l.dy + l.dz * l.dz;
    l.rs = a.radius + b.radius;
    return l.d2 < l.rs * l.rs;  // apart: most near pairs of the contact margin end here
  };
  // pass 1: the total volume (it scales the damping of every pair in pass 2)
  double total = 0.0;
  for (const SpherePairContact& p : held_) {
    Local l;
    if (!place(p, l)) continue;
    const float volume =
        sphere_overlap(std::sqrt(l.d2), p.sphere_a_local.radius, p.sphere_b_local.radius).volume;
    if (volume > 0.f) total += static_cast<double>(volume);
  }

  PenaltyResult result;
  result.total_volume = total;
  if (!(total > 0.0)) return result;

  const auto to_a = [&a_from_world](const BodyMotion& m) {
    return BodyMotion{transform_point(a_from_world, m.center_of_mass_world),
                      rotate(a_from_world.rotation, m.linear_velocity_world),
                      rotate(a_from_world.rotation, m.angular_velocity_world)};
  };
  const BodyMotion tool = to_a(input.tool);
  const BodyMotion other = to_a(input.other);
  detail::PenaltySum sum(input, total, tool, other);
  // pass 2: the same per-pair terms in float, fed to the law in double
  for (const SpherePairContact& p : held_) {
    Local l;
    if (!place(p, l) || !selection.includes(p)) continue;
    const float d = std::sqrt(l.d2);
    const SphereOverlap<float> o = sphere_overlap(d, p.sphere_a_local.radius, p.sphere_b_local.radius);
    if (!(o.volume > 0.f)) continue;
    float nx, ny, nz;
    if (d > 1e-6f * l.rs) {
      const float inv = 1.f / d;
      nx = l.dx * inv;
      ny = l.dy * inv;
      nz = l.dz * inv;
    } else {
      const Vec3 n = held_normal_in_a(p);
      nx = static_cast<float>(n.x);
      ny = static_cast<float>(n.y);
      nz = static_cast<float>(n.z);
    }
    const float off = o.centroid_offset;
    ++result.pair_count;
    sum.add(static_cast<double>(o.volume), static_cast<double>(o.area),
            Vec3{static_cast<double>(nx), static_cast<double>(ny), static_cast<double>(nz)},
            Vec3{static_cast<double>(p.sphere_a_local.x + nx * off),
                 static_cast<double>(p.sphere_a_local.y + ny * off),
                 static_cast<double>(p.sphere_a_local.z + nz * off)});
  }
  result.pushing_pairs = sum.pushing_pairs;
  const Vec3& force = sum.force;
  const Vec3& torque = sum.torque;
  result.wrench.force = rotate(world_from_a.rotation, force);
  result.wrench.torque = rotate(world_from_a.rotation, torque);
  return result;
}

}  // namespace uh::forcecomp
