#pragma once
// The per-pair terms of both force laws (penalty_force.hpp), in one place: evaluate_penalty() (a
// pair list from a query) and HeldContactSet::evaluate() (held pairs at the current poses) feed
// each pair through PenaltySum, so the 3-DOF and 6-DOF modes, the single-rate and the multi-rate
// paths render the same law. Real-time safe.

#include <algorithm>

#include "uh/core/math.hpp"
#include "uh/forcecomp/penalty_force.hpp"

namespace uh::forcecomp::detail {

// Sums f_ij n_ij and the torques over the pairs of one evaluation. Every frame-dependent input
// (motions, normals, points) must be in one frame; the sums come out in it.
class PenaltySum {
 public:
  // `total_volume` = Vol_total of the pairs that will be added; `tool`, `other` in the pairs' frame
  PenaltySum(const PenaltyInput& input, double total_volume, const BodyMotion& tool, const BodyMotion& other)
      : tool_(tool),
        other_(other),
        sign_(input.tool_side == ContactSide::kB ? 1.0 : -1.0),
        six_dof_(input.mode == ForceMode::k6Dof),
        gradient_(input.law == ForceLaw::kGradient) {
    const double calibration = gradient_ ? coverage_product(input) : 1.0;
    per_area_ = input.stiffness / calibration;
    per_volume_ = input.force_scale;
    damping_per_volume_ = input.damping / std::max(total_volume, damping_full_volume(input) * calibration);
  }

  // One pair with positive volume: lens volume, intersection disk area (pi a^2), the unit normal
  // from A's sphere towards B's and a point on the centre line (the lens centroid).
  void add(double volume, double area, const Vec3& normal_a_to_b, const Vec3& point) {
    const Vec3 n = sign_ * normal_a_to_b;  // out of the other object, for the tool
    const double spring = gradient_ ? per_area_ * area : per_volume_ * volume;
    const double vel = dot(tool_.point_velocity(point) - other_.point_velocity(point), n);
    const double f = spring - damping_per_volume_ * vel * volume;
    if (!(f > 0.0)) return;  // never pull the objects together
    ++pushing_pairs;
    const Vec3 fn = f * n;
    force += fn;
    if (six_dof_) torque += cross(point - tool_.center_of_mass_world, fn);
  }

  Vec3 force{};
  Vec3 torque{};
  std::int32_t pushing_pairs = 0;

 private:
  BodyMotion tool_;
  BodyMotion other_;
  double sign_;
  bool six_dof_;
  bool gradient_;
  double per_area_ = 0.0;
  double per_volume_ = 0.0;
  double damping_per_volume_ = 0.0;
};

}  // namespace uh::forcecomp::detail
