#pragma once
/// \file
/// The trace of an exploration: per haptic tick, the device position, the force commanded and the
/// script's own label of its phase. The estimators read nothing else.

#include <cstdint>
#include <limits>
#include <vector>

#include "uh/core/math.hpp"
#include "uh/exploration/explore_options.hpp"

namespace uh::exploration {

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

}  // namespace uh::exploration
