#pragma once
/// \file
/// ContactCompliance: what a soft object's simulation tells a tool's haptic thread about the
/// contact it gives way under (issue 26; docs/deformables.md, "What the hand feels"). Plain data,
/// handed over in a LatestValue (simulation thread -> the tool's haptic thread).

#include <cstdint>

#include "uh/core/math.hpp"

namespace uh::controllers {

struct ContactCompliance {
  /// The part of the tool's felt force [N, world] the object's last step took as its loads (the
  /// object's share of it): where the object now is, in the tree its step published, is its
  /// response to this force.
  Vec3 force_world{};
  double share = 0.0;  ///< the object's share of the tool's contact, [0, 1]
  /// How far the contact moves per newton more within the next step, along the force [m/N] (0:
  /// unknown, or no contact).
  double compliance_m_per_n = 0.0;
  /// The contact's normal [world, unit, out of the object] and how fast the contact moved into the
  /// object over the step [m/s, along -normal]: the motion the next step carries on under the same
  /// loads, which the haptic thread extrapolates for at most `period_s` [s] (one step).
  Vec3 normal_world{};
  double recede_m_per_s = 0.0;
  double period_s = 0.0;
  /// The simulation step that took the force and published the tree the contact is on (1, 2, ...;
  /// 0: none yet).
  std::uint64_t step = 0;
};

}  // namespace uh::controllers
