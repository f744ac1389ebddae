#pragma once
/// \file
/// The force section of a scene (`force`, docs/scenes.md): how the force controller follows the
/// tool between collision frames, its safety options, the virtual coupling and the proxy. Plain
/// data, described here and used by uh::controllers (ForceController, ToolProxy).

#include <cstdint>

#include "uh/forcecomp/force_safety.hpp"
#include "uh/forcecomp/virtual_coupling.hpp"
#include "uh/forcecomp/wrench_model.hpp"

namespace uh::scene {

/// Options of a ToolProxy (aggregate; scene field `force.proxy`, docs/scenes.md).
struct ToolProxyOptions {
  /// Render through the proxy (the default), or the penalty path when false. A scene that enables
  /// force.coupling gets the penalty path with the coupling unless it asks for the proxy too.
  bool enabled = true;
  /// Most any point of the tool moves in one collision step [m] (a hand faster than step_m times
  /// the collision rate drags the proxy behind it). The world's contact margin is raised to it.
  double step_m = 0.002;
  /// How far the proxy's spheres may overlap the object's [m]: the proxy rests this deep.
  double penetration_m = 0.0001;
  /// Most sphere pairs a step takes as constraints (the nearest; the rest shrink the step).
  std::int32_t max_constraints = 4096;
  /// The length over which the packed surface is smoothed [m] (0: the spheres' union as it is):
  /// each tool sphere near the object also gets a constraint on the soft minimum of its gaps,
  /// -e log sum exp(-gap_i / e), which lies above the caps of a packed face by at most
  /// e log(count) and rounds the kinks between them, so a tool sliding on it does not ride over
  /// the packing's grain. It only adds constraints: the pairs' own still hold. Keep it well below
  /// step_m (the pairs beyond the margin are not in the sum). A ball sliding on a face packed with
  /// 10,000 spheres ripples 19 % of its normal force on the spheres' union, 11 % at 0.2 mm.
  double smoothing_m = 0.0002;
};

/// How a multi-rate tick computes the contact wrench from the newest collision frame.
enum class TickForce {
  /// Default. The frame's local wrench model (forcecomp/wrench_model.hpp), built on the collision
  /// thread, evaluated at the current pose in constant time and blended between frames.
  kModel,
  /// Every held sphere pair re-evaluated at the current pose (HeldContactSet): O(pairs) per tick,
  /// the reference the model is measured against.
  kExact,
};

/// Options of a ForceController (aggregate; designated initialisers).
struct ForceControllerOptions {
  /// Follow the tool between collision frames (multi-rate), as `tick_force` says. When false,
  /// the force computed from the newest collision frame is held until the next frame.
  bool multi_rate = true;
  TickForce tick_force = TickForce::kModel;
  forcecomp::WrenchModelOptions model{};  ///< trust range, fallback and blend of kModel
  /// Measurement only: with kModel, also re-evaluate the held pairs every tick and record how far
  /// the model's force is from it (ForceControllerStats::model_error_*). The tick is then O(pairs).
  bool check_model = false;
  /// NaN guard and contact-age watchdog applied before the command leaves the controller (the
  /// limits are the haptic manager's limit chain, applied to the summed command).
  forcecomp::ForceSafetyOptions safety{};
  /// Optional spring-damper between the handle and a simulated tool (proxy).
  bool use_coupling = false;
  forcecomp::VirtualCouplingOptions coupling{};
  /// The 6-DOF god-object (uh/controllers/tool_proxy.hpp): when enabled, the device feels the spring
  /// of `coupling` (its passivity-bounded stiffness) between the handle and the proxy instead of
  /// the penalty forces, and the tool in the collision world is the proxy.
  ToolProxyOptions proxy{};
};

}  // namespace uh::scene
