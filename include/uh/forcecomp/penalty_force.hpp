#pragma once
/// \file
/// The volumetric penalty force and torque on a tool, evaluated from a list of overlapping
/// leaf-sphere pairs, with one of two laws (ForceLaw). For every pair ij with lens volume vol_ij,
/// intersection disk area A_ij = pi a_ij^2, unit normal n_ij along the centre line (pointing out of
/// the other object, for the tool) and a point C_ij on the centre line (the lens centroid):
///
///     gradient (default):  s_ij = k / (c_A c_B) * A_ij                                   [N]
///     paper (eq. 1):       s_ij = eps_c * vol_ij                                         [N]
///     f_ij   = max(s_ij - eps_d * vel_ij * (vol_ij / max(Vol_total, V_d')), 0)           [N]
///     F      = sum_ij f_ij * n_ij                                                        [N]
///     tau    = sum_ij (C_ij - A_m) x (f_ij * n_ij)                                       [N m]
///
/// with Vol_total = sum_ij vol_ij, A_m the tool's centre of mass, vel_ij the velocity of the tool
/// relative to the other object at C_ij projected on n_ij (positive when separating), c_A c_B the
/// product of the two packings' coverages (`coverage_product`) and V_d' = V_d (paper) or
/// V_d c_A c_B (gradient: the ramp compares the calibrated volume Vol_total / (c_A c_B) with V_d).
///
/// Gradient law. Since the spheres of one packing are disjoint, the packings' overlap volume is
/// exactly V = sum_ij vol_ij(d_ij), and dvol/dd = -A (the lens kernel's area), so
/// -dV/dx_B = sum_ij A_ij n_ij: the static force k / (c_A c_B) * sum A_ij n_ij is minus the gradient
/// of the potential U = k V / (c_A c_B) with respect to B's position, hence conservative (its work
/// around any closed path is zero). Rotating B by a small angle w about A_m changes d_ij by
/// w . ((p - A_m) x n_ij) for any point p on the centre line, so the torque sum (C_ij - A_m) x s_ij
/// n_ij is minus the rotational gradient of U too; any point of the centre line (lens centroid or
/// disk centre) gives the same torque and the same vel_ij. k is a pressure [N / L^2]: deep in, a
/// flat face of area S feels k S; a round tip of radius r pressed delta in feels about 2 pi r k delta.
/// A packing fills a share c (its coverage) of its mesh, so V ~ c_A c_B V_mesh and dV ~ c_A c_B
/// dV_mesh: dividing by c_A c_B makes the force independent of the sphere count.
///
/// Paper law (Bissel et al. 2018, eq. 1). The volume-weighted pair normals; the static part is
/// not the gradient of the overlap volume (over 8 mesh pairs its direction is 6.6 deg off the true
/// mesh gradient in the median and up to 145 deg, against 1.7 and 16 deg for the gradient law,
/// docs/benchmarks.md) and its size grows with the coverage.
///
/// Reading of the damping term. The paper prints `vel_ij eps_d / Vol_total`, which is not
/// dimensionally consistent with `vol_ij eps_c`. We implement `eps_d * vel_ij * (vol_ij / Vol_total)`:
/// each pair takes a share of the damping proportional to its share of the overlap volume. The
/// shares sum to one, so when all normals agree the damping force is exactly eps_d * v, an ordinary
/// linear damper with eps_d in N s / L that does not depend on how finely the objects are packed
/// or on how many pairs overlap; the damping reacts to motion only while in contact; and the
/// per-pair clamp at zero keeps the force from ever pulling the objects together (no sticking
/// when separating quickly). Both laws share it.
///
/// Onset. Because the shares sum to one from the first touching pair on, that reading puts the
/// full damping force eps_d * v on at the instant of contact: a step. `damping_full_volume`
/// V_d > 0 (ForceParams' default) replaces Vol_total by max(Vol_total, V_d') in the share: below
/// it the damping is eps_d * v * Vol_total / V_d', which starts at zero with the overlap; from
/// there on it is the reading above.
///
/// The damping part only removes energy (f_ij falls when the tool moves in, rises when it moves
/// out, and the clamp only removes force).
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
  ForceLaw law = ForceLaw::kGradient;  ///< which static term (see above)
  double stiffness = 0.0;              ///< gradient law: k [N / L^2]
  double force_scale = 0.0;            ///< paper law: eps_c [N / L^3]
  /// c_A c_B, the product of the two packings' coverages (sphere volume / mesh volume), in (0, 1];
  /// the gradient law divides by it. Anything else (unknown) counts as 1.
  double coverage_product = 1.0;
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

/// The c_A c_B in effect: a non-finite or non-positive setting counts as 1 (no calibration).
inline double coverage_product(const PenaltyInput& input) {
  const double c = input.coverage_product;
  return c > 0.0 && c <= 1e300 ? c : 1.0;
}

/// Evaluates the law `input.law` over `pairs` (world-frame normals and centroids as written by Collette).
/// Pairs with zero or non-finite volume are skipped. No limits are applied here: see ForceSafety.
/// Any thread; real-time safe; O(pairs).
PenaltyResult evaluate_penalty(std::span<const SpherePairContact> pairs, const PenaltyInput& input);

/// Same over the valid pairs of a ContactFrame. When the frame is `truncated`, only the stored pairs
/// contribute (the force is then an underestimate).
PenaltyResult evaluate_penalty(const ContactFrame& frame, const PenaltyInput& input);

}  // namespace uh::forcecomp
