#pragma once
// The energy balance of a simulated hand (sim-hand) that reacts to the force: what reaches the
// hand through the handle over a session (the passivity checks, docs/forcecomp.md).

#include <gtest/gtest.h>

#include "uh/controllers/haptic_session.hpp"
#include "uh/controllers/scene.hpp"

namespace uh::controllers::testing {

// The hand device's own damping [N s/m], as its scene's sim-hand config sets it: the real one,
// not what the coupling is told.
inline double hand_device_damping(const Scene& scene) {
  const auto damping = scene.tool().device.config.number("device_damping", 0.0);
  EXPECT_TRUE(damping) << damping.error().message;
  return damping ? *damping : 0.0;
}

// The energy that reaches the hand through the handle over the run [J]: the motors' work less what
// the device's mechanism dissipates meanwhile (its damping b times the squared speed's integral
// over the ticks in contact, counted low; free motion's is left out).
inline double energy_into_hand(const SessionReport& r, double device_damping) {
  return r.work_on_hand_j - device_damping * r.contact_squared_speed_integral;
}

}  // namespace uh::controllers::testing
