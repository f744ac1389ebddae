#pragma once
/// \file
/// Exploration: a scripted hand explores each object of a scene on a simulated device in
/// simulated time (press and release, strokes in two directions at a set speed and normal force,
/// a contour follow, taps), and the object's material is estimated back from the trace of the
/// device's position and the force it was commanded, alone: stiffness, static and dynamic
/// friction, texture period and ripple. What `uh explore` runs (docs/exploration.md).
///
/// The estimators read only the trace (ExploreTrace) and the script's own labels of its phases;
/// they never read the scene's material values.

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "uh/controllers/haptic_session.hpp"
#include "uh/controllers/scene.hpp"
#include "uh/core/math.hpp"
#include "uh/core/result.hpp"

namespace uh::controllers {

/// Where on the object the hand goes in (planned from the packed shape's bounds, never its material).
struct ExploreSite {
  enum class From : std::uint8_t {
    kTop,   ///< down onto the top, near the middle of the footprint moved by `offset_m` (and the seed)
    kSide,  ///< horizontally towards the footprint's vertical centre line, at a height and an azimuth
  };
  From from = From::kTop;
  double offset_m[2] = {0.0, 0.0};  ///< top: where, from the footprint's middle along x and y [m]
  double height_fraction = 0.5;     ///< side: at this fraction of the object's height (0 base, 1 top)
  double azimuth_rad = 0.0;         ///< side: coming from this direction about the vertical (0 = from +x)
};

/// The path the contour follow takes after the strokes.
enum class ContourPath : std::uint8_t {
  kCircle,      ///< one circle of `contour_radius_m` in the tangent plane
  kAroundAxis,  ///< once around the footprint's vertical centre line, level, along the surface (a side site)
  kNone,
};

/// Settings of the exploration script (options aggregate).
struct ExploreOptions {
  ExploreSite site{};
  /// Press this far past the first touch, then release [m]: every material is read over the same
  /// depths, so the packing's fill under the surface (which grows with depth under a packed face)
  /// scales every stiffness alike. Empty: press to the press force (below) instead.
  std::optional<double> press_depth_m = 0.0025;
  /// Press to this normal force (a press to a depth stops there too) [N]. Empty: to 90 % of the
  /// session's force limit (the smallest of the device's, the tool's and the safety limit), so that
  /// a stiff surface is pressed as deep as the limit lets and no sample the fit reads is clamped.
  std::optional<double> press_force_n;
  double press_speed_m_per_s = 0.004;  ///< speed of the press and release [m/s]
  /// How many presses: the first at the site, the others round it, `press_spread_m` away on the
  /// diagonals between the stroke axes, the hand moving between them in the air. A press reads the
  /// packing's grain under the tip as well as the material (a few percent from spot to spot on a
  /// packed face): the stiffness is the median of the presses'.
  int presses = 5;
  double press_spread_m = 0.008;       ///< how far from the site the other presses are [m]
  double stroke_force_n = 2.0;         ///< normal force held while stroking [N]
  double stroke_speed_m_per_s = 0.02;  ///< stroke speed [m/s]
  double stroke_length_m = 0.024;      ///< length of each stroke [m]
  /// Length of the strokes along the second axis [m]; as `stroke_length_m` when empty.
  std::optional<double> second_stroke_length_m;
  /// A stroke ends early where the surface's normal has turned this far from where it began (an
  /// edge, as a finger stops at a rim) [rad]; strokes go their whole length when empty.
  std::optional<double> stroke_stops_at_edge_rad;
  int stroke_legs = 4;  ///< how many of the four strokes (+e1, -e1, +e2, -e2) to make, in that order
  /// Each axis's strokes run through the site: the hand moves in the air to half a stroke before it
  /// and strokes across and back, so that on a round object they cross its top rather than run down
  /// one flank; the contour is then made at the site again. Off: each stroke starts where the last
  /// ended, the first at the site.
  bool strokes_through_site = true;
  /// The stroke axes: top sites turn e1 = +x by this about the vertical (the seed's turn when
  /// empty); side sites stroke along e1 = up and e2 = the level tangent.
  std::optional<double> stroke_turn_rad;
  ContourPath contour = ContourPath::kCircle;
  double contour_radius_m = 0.005;              ///< the circle's radius [m]
  std::optional<double> contour_speed_m_per_s;  ///< the contour's speed [m/s]; the stroke speed when empty
  int taps = 3;                        ///< taps at the end
  double tap_speed_m_per_s = 0.03;     ///< [m/s]
  std::optional<double> haptic_hz;     ///< override of the scene's haptic rate [Hz]
  int ticks_per_collision_step = 1;    ///< haptic ticks per collision step (simulated time)
  double max_seconds = 40.0;           ///< the script's whole budget of simulated time [s]
  /// Moves where on the object the exploration happens (by up to 3 mm; a side site's height by up
  /// to 1 mm) and turns the pair of
  /// stroke directions about the vertical (unless `stroke_turn_rad`); the same seed gives the same run.
  std::uint64_t seed = 1;
};

/// The phases of the script, as labelled in the trace.
enum class ExplorePhase : std::uint8_t {
  kApproach,
  kPress,
  kRelease,
  kSeat,
  kHold,
  kStroke,
  kContour,
  kLift,
  kTap,
  kReturn,
  kDone,
  kMove,  ///< in the air to the next press or stroke (up to the start's level, then across)
};

/// One haptic tick of an exploration: the device position and the force commanded (world frame,
/// which the exploration makes the device frame).
struct ExploreSample {
  double time_s = 0.0;
  Vec3 position{};  ///< handle position [m]
  Vec3 force{};     ///< force commanded to the device [N]
  ExplorePhase phase = ExplorePhase::kApproach;
  /// which stroke (0..3: +e1, -e1, +e2, -e2) or, while pressing, which press (0..); -1 otherwise
  std::int32_t leg = -1;
};

struct ExploreTrace {
  std::vector<ExploreSample> samples;
  ExploreOptions options{};
  /// The smallest force limit the commanded forces went through (the device's, the tool's, the
  /// safety limit) [N]: a sample near it may be clamped and says nothing of the material.
  double force_limit_n = std::numeric_limits<double>::infinity();
  Vec3 stroke_axes[2]{};  ///< e1, e2: the stroke directions
  Vec3 axis_point{};      ///< a point of the footprint's vertical centre line (kAroundAxis goes round it)
};

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
  /// The share of the contour's ripple explained by the plane wave the strokes found (a grating
  /// explains much of it; a random texture or a packing's grain little): texture_period_m is
  /// reported only above 0.45.
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

/// One object explored.
struct ObjectExploration {
  std::string object;
  MaterialEstimate estimate;
  ExploreTrace trace;
  double work_on_hand_j = 0.0;  ///< energy the device put into the hand over the whole (closed) script [J]
  double simulated_s = 0.0;     ///< simulated time the script took [s]
  std::uint64_t haptic_ticks = 0;
};

/// Explores object `object_name` of `scene` (every object when empty), each alone with the
/// scene's tool, on a simulated hand that follows the script; stepped, in simulated time.
Result<std::vector<ObjectExploration>> explore_scene(const Scene& scene, const std::string& object_name,
                                                     const ExploreOptions& options,
                                                     const SessionOptions& session = {});

}  // namespace uh::controllers
