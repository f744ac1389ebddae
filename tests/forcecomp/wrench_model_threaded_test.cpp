// The wrench model crosses from a collision thread to a haptic thread through LatestValue, as the
// ForceController sends it; run under ThreadSanitizer (label "threads").

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <thread>
#include <vector>

#include "pair_reference.hpp"
#include "uh/core/latest_value.hpp"
#include "uh/forcecomp/wrench_model.hpp"

namespace uh::forcecomp {
namespace {

TEST(WrenchModelThreads, ModelsCrossThroughLatestValueWhole) {
  // one sphere of the other object, one of the tool pressing down into it: the model's static
  // force is along +z and grows with the depth, so a torn model would show as an inconsistent one
  const std::vector<Sphere> other{test::sphere(0, 0, 0, 0.125)};
  const std::vector<Sphere> tool{test::sphere(0, 0, 0, 0.0625)};
  constexpr int kFrames = 2000;
  LatestValue<WrenchModel> handoff;
  std::atomic<bool> done{false};

  std::thread collision([&] {
    for (int k = 1; k <= kFrames; ++k) {
      const double depth = 0.01 + 0.09 * k / kFrames;
      const Pose world_from_tool{Quat{}, {0, 0, 0.1875 - depth}};
      PenaltyInput in;
      in.stiffness = 100.0;
      in.tool.center_of_mass_world = world_from_tool.position;
      const auto pairs = test::brute_force_pairs(other, Pose{}, tool, world_from_tool);
      WrenchModel& m = handoff.write_buffer();
      m = build_wrench_model(pairs, Pose{}, world_from_tool, in);
      m.sequence = static_cast<std::uint64_t>(k);
      m.time_s = 0.001 * k;
      handoff.publish();
    }
    done.store(true);
  });

  WrenchModelRenderer renderer;
  std::uint64_t last_sequence = 0;
  int taken = 0;
  double now = 0.0;
  bool consistent = true;
  while (true) {
    const bool finished = done.load();
    const bool arrived = handoff.update();
    if (arrived) {
      const WrenchModel& m = handoff.read_buffer();
      // sequences only grow; the force belongs to the depth of the same frame
      consistent = consistent && m.sequence > last_sequence && m.contact && m.wrench.force.z > 0.0;
      const double depth = 0.01 + 0.09 * static_cast<double>(m.sequence) / kFrames;
      const double distance = 0.1875 - depth;
      const double expected_area = kPi / 4.0 * (0.1875 * 0.1875 - distance * distance) *
                                   (distance * distance - 0.0625 * 0.0625) / (distance * distance);
      consistent =
          consistent && std::abs(m.wrench.force.z - 100.0 * expected_area) < 1e-9 * 100.0 * expected_area;
      last_sequence = m.sequence;
      renderer.take(m);
      ++taken;
    }
    BodyMotion at;
    at.center_of_mass_world = {0, 0, 0.14};
    const Wrench w = renderer.render(now += 0.0005, Quat{}, at);
    consistent = consistent && std::isfinite(w.force.z) && std::isfinite(w.torque.x);
    if (finished && !arrived) break;  // everything published before `finished` was read is taken
  }
  collision.join();
  EXPECT_TRUE(consistent);
  EXPECT_GT(taken, 0);
}

}  // namespace
}  // namespace uh::forcecomp
