#pragma once
/// \file
/// The settings of the exploration script: where the hand goes in and how it presses, strokes,
/// follows a contour and taps (docs/exploration.md).

#include <cstdint>
#include <optional>

namespace uh::exploration {

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

}  // namespace uh::exploration
