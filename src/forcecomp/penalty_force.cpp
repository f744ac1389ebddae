#include "uh/forcecomp/penalty_force.hpp"

#include <algorithm>
#include <cmath>

#include "penalty_terms.hpp"

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

  detail::PenaltySum sum(input, total, input.tool, input.other);
  for (const SpherePairContact& p : pairs) {
    const double vol = static_cast<double>(p.volume);
    if (!(vol > 0.0) || !std::isfinite(vol)) continue;
    ++result.pair_count;
    sum.add(vol, static_cast<double>(p.area), to_vec3(p.normal_world), to_vec3(p.centroid_world));
  }
  result.wrench = {sum.force, sum.torque};
  result.pushing_pairs = sum.pushing_pairs;
  return result;
}

PenaltyResult evaluate_penalty(const ContactFrame& frame, const PenaltyInput& input) {
  return evaluate_penalty(frame.pairs(), input);
}

}  // namespace uh::forcecomp
