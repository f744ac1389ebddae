#pragma once
/// \file
/// The volumetric penalty force and torque of UnrealHaptics (eq. 1 and 2), evaluated from a list of
/// overlapping leaf-sphere pairs.
///
/// For every pair ij with lens volume vol_ij, unit normal n_ij (pointing out of the other object,
/// for the tool) and lens centroid C_ij:
///
///     f_ij   = max(eps_c * vol_ij - eps_d * vel_ij * (vol_ij / Vol_total), 0)        [N]
///     F      = sum_ij f_ij * n_ij                                                    [N]
///     tau    = sum_ij (C_ij - A_m) x (f_ij * n_ij)                                   [N m]
///
/// with Vol_total = sum_ij vol_ij, A_m the tool's centre of mass and vel_ij the velocity of the tool
/// relative to the other object at C_ij, projected on n_ij (positive when separating).
///
/// Reading of the damping term. The paper prints `vel_ij eps_d / Vol_total`, which is not
/// dimensionally consistent with `vol_ij eps_c`. We implement `eps_d * vel_ij * (vol_ij / Vol_total)`:
/// each pair takes a share of the damping proportional to its share of the overlap volume. The
/// shares sum to one, so when all normals agree the damping force is exactly eps_d * v, an ordinary
/// linear damper with eps_d in N s / L that does not depend on how finely the objects are packed
/// or on how many pairs overlap; the damping reacts to motion only while in contact; and the
/// per-pair clamp at zero keeps the force from ever pulling the objects together (no sticking
/// when separating quickly).
///
/// Onset. Because the shares sum to one from the first touching pair on, that reading puts the
/// full damping force eps_d * v on at the instant of contact: a step (measured in the continuity
/// scene, which therefore renders without damping). `damping_full_volume` V_d > 0 replaces
/// Vol_total by max(Vol_total, V_d) in the share: below V_d the damping is eps_d * v * Vol_total / V_d,
/// which starts at zero with the overlap; from V_d on it is the reading above. A V_d of a few
/// percent of the volume the tool typically sinks in keeps deep contacts unchanged.
///
/// The static part sum_ij eps_c vol_ij n_ij is conservative (per-pair forces along centre lines are
/// the gradient of eps_c * total overlap volume), so it stores and returns energy; the damping
/// part only removes energy.
///
/// Real-time safe: no allocation, lock, throw or log.

#include <cstdint>
#include <span>

#include "uh/core/contact.hpp"
#include "uh/forcecomp/force_params.hpp"
#include "uh/forcecomp/wrench.hpp"

namespace uh::forcecomp {

/// Inputs of one penalty evaluation besides the pair list (options aggregate).
struct PenaltyInput {
  double force_scale = 0.0;           ///< eps_c [N / L^3]
  double damping = 0.0;               ///< eps_d [N s / L]
  double damping_full_volume = 0.0;   ///< V_d [L^3]: damping shares are vol_ij / max(Vol_total, V_d)
  ForceMode mode = ForceMode::k6Dof;  ///< k3Dof leaves the torque at zero
  ContactSide tool_side = ContactSide::kB;  ///< the object whose force is computed
  BodyMotion tool{};                  ///< the tool's centre of mass and velocities (world frame)
  BodyMotion other{};                 ///< the other object's motion; default: static
};

/// What one penalty evaluation produced. Trivially copyable.
struct PenaltyResult {
  Wrench wrench{};              ///< on the tool, world frame; torque about its centre of mass
  double total_volume = 0.0;    ///< Vol_total, sum of the pair volumes used [L^3]
  std::int32_t pair_count = 0;  ///< pairs with positive volume
  std::int32_t pushing_pairs = 0;  ///< pairs whose f_ij was positive after the clamp at zero
};

/// The V_d in effect: a non-finite or negative setting counts as 0 (the paper's reading).
inline double damping_full_volume(const PenaltyInput& input) {
  const double v = input.damping_full_volume;
  return v > 0.0 && v < 1e300 ? v : 0.0;
}

/// Evaluates eq. 1 and 2 over `pairs` (world-frame normals and centroids as written by Collette).
/// Pairs with zero or non-finite volume are skipped. No limits are applied here: see ForceSafety.
/// Any thread; real-time safe; O(pairs).
PenaltyResult evaluate_penalty(std::span<const SpherePairContact> pairs, const PenaltyInput& input);

/// Same over the valid pairs of a ContactFrame. When the frame is `truncated`, only the stored pairs
/// contribute (the force is then an underestimate).
PenaltyResult evaluate_penalty(const ContactFrame& frame, const PenaltyInput& input);

}  // namespace uh::forcecomp
