#include "uh/forcecomp/penalty_force.hpp"

#include <algorithm>
#include <cmath>

namespace uh::forcecomp {

namespace {

Vec3 to_vec3(const float (&v)[3]) {
  return {static_cast<double>(v[0]), static_cast<double>(v[1]), static_cast<double>(v[2])};
}

}  // namespace

PenaltyResult evaluate_penalty(std::span<const SpherePairContact> pairs, const PenaltyInput& input) {
  PenaltyResult result;
  // first pass: Vol_total, needed by every pair's damping share
  double total = 0.0;
  for (const SpherePairContact& p : pairs) {
    const double v = static_cast<double>(p.volume);
    if (v > 0.0 && std::isfinite(v)) total += v;
  }
  result.total_volume = total;
  if (!(total > 0.0)) return result;

  const double sign = input.tool_side == ContactSide::kB ? 1.0 : -1.0;
  const double damping_per_volume = input.damping / std::max(total, damping_full_volume(input));
  const bool six_dof = input.mode == ForceMode::k6Dof;
  for (const SpherePairContact& p : pairs) {
    const double vol = static_cast<double>(p.volume);
    if (!(vol > 0.0) || !std::isfinite(vol)) continue;
    ++result.pair_count;
    const Vec3 n = sign * to_vec3(p.normal_world);  // out of the other object, for the tool
    const Vec3 c = to_vec3(p.centroid_world);
    const double vel = dot(input.tool.point_velocity(c) - input.other.point_velocity(c), n);
    const double f = input.force_scale * vol - damping_per_volume * vel * vol;
    if (!(f > 0.0)) continue;  // never pull the objects together
    ++result.pushing_pairs;
    const Vec3 fij = f * n;
    result.wrench.force += fij;
    if (six_dof) result.wrench.torque += cross(c - input.tool.center_of_mass_world, fij);
  }
  return result;
}

PenaltyResult evaluate_penalty(const ContactFrame& frame, const PenaltyInput& input) {
  const auto count = static_cast<std::size_t>(std::clamp(frame.pair_count, 0, ContactFrame::kMaxPairs));
  return evaluate_penalty(std::span<const SpherePairContact>(frame.pairs.data(), count), input);
}

}  // namespace uh::forcecomp
