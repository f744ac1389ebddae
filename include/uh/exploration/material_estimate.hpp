#pragma once
/// \file
/// The material estimated back from an exploration's trace alone (the device's positions, the
/// commanded forces and the script's phase labels), never from the scene's material values.

#include <optional>
#include <vector>

#include "uh/exploration/explore_trace.hpp"

namespace uh::exploration {

/// What the estimators found on one object. Optional fields are empty when the trace holds no
/// evidence (no contact, no significant ripple).
struct MaterialEstimate {
  /// slope of normal force against depth at first touch, the median of the presses'
  std::optional<double> stiffness_n_per_mm;
  std::vector<double> stiffness_per_press_n_per_mm;  ///< each press's slope, in the order pressed
  /// How far past first contact the presses went (their median) [m]: short of `press_depth_m` when
  /// the press force stopped them first (a stiff surface under a low force limit), and then the
  /// stiffness is read over shallower depths, where a packed face is not yet full (it reads low).
  std::optional<double> press_reach_m;
  /// The damping felt along the normal [N s/m]: per press, the normal force over the deeper part
  /// of the press (60 % to 95 % of its depth) fitted as a smooth function of depth plus this times
  /// the speed into the surface (the loop between the press and its release at
  /// `press_speed_m_per_s`); the median of the presses. Under the volumetric penalty law it is the
  /// material's `damping` times the overlap-weighted mean cos^2 between the sphere pairs' normals
  /// and the contact normal: the material's value on a smooth face, 11-14 % less on a packed flat
  /// face (docs/exploration.md).
  std::optional<double> damping_n_s_per_m;
  std::vector<double> damping_per_press_n_s_per_m;  ///< each press's, in the order pressed
  std::optional<double> friction_static;     ///< tangential over normal force at breakaway
  std::optional<double> friction_dynamic;    ///< tangential over normal force while sliding
  std::optional<double> texture_period_m;    ///< dominant spatial period of the normal force ripple
  double texture_ripple_n = 0.0;             ///< RMS of the normal force ripple while sliding [N]
  double period_axis_m[2] = {0.0, 0.0};      ///< dominant apparent period along each stroke axis, 0 = none
  /// Per axis, the share of its strokes' ripple one sinusoid at its peak explains (0 = no peak): a
  /// grating's ripple along a line is one sinusoid; an axis counts as seeing a wave above 0.5.
  double sine_share_axis[2] = {0.0, 0.0};
  /// The share of the contour's ripple explained by the plane wave the strokes found, less the best
  /// share the same search finds with its candidates turned to other directions (chance: a grating
  /// explains much of it in its own direction only, a random texture or a packing's grain as much
  /// in others): texture_period_m is reported only from 0.25.
  double texture_wave_share = 0.0;
  double ripple_axis_n[2] = {0.0, 0.0};  ///< RMS ripple of the strokes along each axis [N]
};

/// The normal force at which a press stops: `press_force_n`, by default 90 % of `force_limit_n`
/// (the smallest force limit between the session and the device) [N].
double press_stop_force_n(const ExploreOptions& options, double force_limit_n);

/// Estimates the material from a trace alone (the device's positions, the commanded forces and the
/// script's phase labels).
MaterialEstimate estimate_material(const ExploreTrace& trace);

/// The force felt while stroking at one tick: split along the motion (for plots).
struct StrokeForce {
  double time_s = 0.0;
  double normal_n = 0.0;      ///< the force across the motion [N]
  double tangential_n = 0.0;  ///< the force against the motion [N]
};

/// The strokes' and the contour's samples of a trace as normal and tangential force.
std::vector<StrokeForce> stroke_forces(const ExploreTrace& trace);

}  // namespace uh::exploration
