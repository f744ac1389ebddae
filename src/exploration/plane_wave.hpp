#pragma once
// Whether the texture the strokes found is a grating: one plane wave over the whole surface must
// also explain the ripple of the normal force along the contour, a third path.

#include "slide.hpp"

namespace uh::exploration {

// How much of the ripple of the normal force along the contour one plane wave explains
struct PlaneWaveFit {
  double share = 0.0;         ///< of the ripple's power (after the circle's slow variation) [0, 1]
  double f1 = 0.0, f2 = 0.0;  ///< the wave vector's spatial frequencies along e1, e2 [1/m]
  /// the best share the same search finds with its candidates turned to other directions (chance)
  double chance = 0.0;
};

// The candidates are the strokes' frequencies `f` (0: the axis saw no wave) with either relative
// sign (a stroke sees |k . e| only), and each axis's alone with the other component searched below
// the strokes' lowest frequency `f_low` (its apparent period too long for a stroke).
//
// The hand holds its force with a loop that follows slow bumps, so part of a texture shows in the
// hand's height rather than in the force: the ripple fitted is the force plus the contact's
// stiffness `stiffness` [N/m] times the hand's height along the normal (what the force would have
// been had the hand not moved), averaged over a quarter millimetre (the passivity controller's
// tick-to-tick cuts are no texture).
PlaneWaveFit fit_plane_wave(const Slide& contour, const Vec3 (&axes)[2], const double (&f)[2], double f_low,
                            double stiffness);

}  // namespace uh::exploration
