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
///
/// The module's parts: the script's settings (explore_options.hpp), its trace (explore_trace.hpp),
/// the estimators (material_estimate.hpp) and the run over a scene (explore_scene.hpp).

#include "uh/exploration/explore_options.hpp"
#include "uh/exploration/explore_scene.hpp"
#include "uh/exploration/explore_trace.hpp"
#include "uh/exploration/material_estimate.hpp"
