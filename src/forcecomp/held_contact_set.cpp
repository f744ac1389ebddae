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

HeldContactSet::HeldContactSet(std::int32_t capacity)
    : capacity_(capacity),
      held_(new SpherePairContact[static_cast<std::size_t>(std::max(capacity, 1))]),
      normal_a_local_(new Vec3[static_cast<std::size_t>(std::max(capacity, 1))]),
      scratch_(new SpherePairContact[static_cast<std::size_t>(std::max(capacity, 1))]),
      packed_(new PackedPair[static_cast<std::size_t>(std::max(capacity, 1))]),
      local_(new LocalPair[static_cast<std::size_t>(std::max(capacity, 1))]) {
  assert(capacity > 0 && "uh::forcecomp::HeldContactSet::HeldContactSet(): capacity must be positive");
}

void HeldContactSet::hold(const ContactFrame& frame) {
  const auto count = static_cast<std::size_t>(std::clamp(frame.pair_count, 0, ContactFrame::kMaxPairs));
  hold(std::span<const SpherePairContact>(frame.pairs.data(), count), frame.sequence, frame.time_s);
  // the frame knows its poses: express the normals in A's frame for the coincident-centre case
  const Quat a_from_world = conjugate(frame.world_from_a.rotation);
  for (std::int32_t i = 0; i < size_; ++i) {
    const float* n = held_[static_cast<std::size_t>(i)].normal_world;
    normal_a_local_[static_cast<std::size_t>(i)] =
        rotate(a_from_world, Vec3{static_cast<double>(n[0]), static_cast<double>(n[1]), static_cast<double>(n[2])});
  }
}

void HeldContactSet::hold(std::span<const SpherePairContact> pairs, std::uint64_t sequence, double time_s) {
  const std::size_t n = std::min(pairs.size(), static_cast<std::size_t>(capacity_));
  dropped_pairs_ += pairs.size() - n;
  std::copy_n(pairs.begin(), n, held_.get());
  for (std::size_t i = 0; i < n; ++i) {
    const Sphere& a = pairs[i].sphere_a_local;
    const Sphere& b = pairs[i].sphere_b_local;
    packed_[i] = {a.x, a.y, a.z, a.radius, b.x, b.y, b.z, b.radius};
  }
  for (std::size_t i = 0; i < n; ++i) {
    const float* nw = held_[i].normal_world;
    // without poses the world normal is the best guess for A's frame (exact when A is unrotated)
    normal_a_local_[i] = {static_cast<double>(nw[0]), static_cast<double>(nw[1]), static_cast<double>(nw[2])};
  }
  size_ = static_cast<std::int32_t>(n);
  sequence_ = sequence;
  time_s_ = time_s;
}

void HeldContactSet::clear() {
  size_ = 0;
  sequence_ = 0;
  time_s_ = 0.0;
}

std::span<const SpherePairContact> HeldContactSet::reevaluate(const Pose& world_from_a, const Pose& world_from_b) {
  for (std::int32_t k = 0; k < size_; ++k) {
    const auto i = static_cast<std::size_t>(k);
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
    const Vec3 u = d > 1e-6 * (ra + rb) ? delta / d : rotate(world_from_a.rotation, normal_a_local_[i]);
    const Vec3 centroid = ca + o.centroid_offset * u;
    out.volume = static_cast<float>(o.volume);
    out.area = static_cast<float>(o.area);
    store(out.normal_world, u);
    store(out.centroid_world, centroid);
  }
  return {scratch_.get(), static_cast<std::size_t>(size_)};
}

PenaltyResult HeldContactSet::evaluate(const Pose& world_from_a, const Pose& world_from_b, const PenaltyInput& input) {
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
  double total = 0.0;
  std::int32_t count = 0;
  for (std::int32_t k = 0; k < size_; ++k) {
    const PackedPair& p = packed_[static_cast<std::size_t>(k)];
    const float bx = r[0][0] * p.bx + r[0][1] * p.by + r[0][2] * p.bz + tx;
    const float by = r[1][0] * p.bx + r[1][1] * p.by + r[1][2] * p.bz + ty;
    const float bz = r[2][0] * p.bx + r[2][1] * p.by + r[2][2] * p.bz + tz;
    const float dx = bx - p.ax, dy = by - p.ay, dz = bz - p.az;
    const float d2 = dx * dx + dy * dy + dz * dz;
    const float rs = p.ar + p.br;
    if (!(d2 < rs * rs)) continue;  // apart: most near pairs of the contact margin end here
    const float d = std::sqrt(d2);
    const float inv = d > 0.f ? 1.f / d : 0.f;
    LocalPair& out = local_[static_cast<std::size_t>(count)];
    const SphereOverlap<float> o = sphere_overlap(d, p.ar, p.br);
    out.volume = o.volume;
    out.area = o.area;
    const float off = o.centroid_offset;
    if (!(out.volume > 0.f)) continue;
    if (d > 1e-6f * rs) {
      out.nx = dx * inv;
      out.ny = dy * inv;
      out.nz = dz * inv;
    } else {
      const Vec3& n = normal_a_local_[static_cast<std::size_t>(k)];
      out.nx = static_cast<float>(n.x);
      out.ny = static_cast<float>(n.y);
      out.nz = static_cast<float>(n.z);
    }
    out.cx = p.ax + out.nx * off;
    out.cy = p.ay + out.ny * off;
    out.cz = p.az + out.nz * off;
    total += static_cast<double>(out.volume);
    ++count;
  }
  local_count_ = count;

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
  for (std::int32_t k = 0; k < local_count_; ++k) {
    const LocalPair& p = local_[static_cast<std::size_t>(k)];
    ++result.pair_count;
    sum.add(static_cast<double>(p.volume), static_cast<double>(p.area),
            Vec3{static_cast<double>(p.nx), static_cast<double>(p.ny), static_cast<double>(p.nz)},
            Vec3{static_cast<double>(p.cx), static_cast<double>(p.cy), static_cast<double>(p.cz)});
  }
  result.pushing_pairs = sum.pushing_pairs;
  const Vec3& force = sum.force;
  const Vec3& torque = sum.torque;
  result.wrench.force = rotate(world_from_a.rotation, force);
  result.wrench.torque = rotate(world_from_a.rotation, torque);
  return result;
}

}  // namespace uh::forcecomp
