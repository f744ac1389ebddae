// The per-tick paths of ForceComp must not allocate (house rule for real-time code).

#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "allocation_counter.hpp"
#include "pair_reference.hpp"
#include "uh/forcecomp/force_component.hpp"
#include "uh/forcecomp/force_safety.hpp"
#include "uh/forcecomp/held_contact_set.hpp"
#include "uh/forcecomp/virtual_coupling.hpp"
#include "uh/forcecomp/wrench_model.hpp"

namespace uh::forcecomp {
namespace {

TEST(RealTime, AllocationCounterSeesAllocations) {
  uh::test::AllocationCounter counter;
  auto p = std::make_unique<std::vector<int>>(10);
  EXPECT_EQ(counter.count(), 2u);
}

TEST(RealTime, TickPathsDoNotAllocate) {
  auto frame = std::make_unique<ContactFrame>();
  frame->resize_pairs(50);
  for (int i = 0; i < 50; ++i) {
    frame->pairs()[static_cast<std::size_t>(i)] = test::make_pair(
        test::sphere(0.01 * i, 0, 0, 0.2), Pose{}, test::sphere(0.01 * i + 0.3, 0.05, 0, 0.15), Pose{}, i, i);
  }
  HeldContactSet held(128);
  ForceComponentOptions options;
  options.params.damping = 1.0;
  const ForceComponent tool(options);
  ForceSafety safety;
  VirtualCoupling coupling;
  coupling.reset(Pose{});
  const Pose moved{Quat{}, {0.001, 0, 0}};
  WrenchModelRenderer renderer;

  uh::test::AllocationCounter counter;
  double sink = 0.0;
  for (int tick = 0; tick < 10; ++tick) {
    const BodyMotion self = tool.body_motion(moved, {0.01, 0, 0}, {0, 0, 0.1});
    if (tick % 5 == 0) held.hold(*frame);
    const PenaltyResult direct = tool.evaluate(*frame, self);
    const PenaltyResult fused = tool.evaluate(held, Pose{}, moved, self);
    const auto pairs = held.reevaluate(Pose{}, moved);
    const PenaltyResult two_step = evaluate_penalty(pairs, tool.penalty_input(self, {}));
    if (tick % 5 == 0) renderer.take(build_wrench_model(*frame, tool.penalty_input(self, {})));
    const Wrench modelled = renderer.render(0.001 * tick, moved.rotation, self);
    sink += modelled.force.x;
    // friction per contact patch: the patches of a frame, a patch's model and its held pairs
    const ContactPatches patches = find_contact_patches(frame->pairs());
    const PatchSelection first{&patches, 0};
    sink += build_wrench_model(frame->pairs(), Pose{}, Pose{}, tool.penalty_input(self, {}), {}, first).wrench.force.x;
    sink += tool.evaluate(held, Pose{}, moved, self, {}, 1.0, first).wrench.force.x;
    const Wrench safe = safety.apply(fused.wrench, 0.001 * tick, 0.0);
    const CouplingOutput out = coupling.step(moved, {}, {}, safe, 0.001);
    sink += direct.wrench.force.x + two_step.wrench.force.x + out.device_wrench.force.x;
  }
  EXPECT_EQ(counter.count(), 0u);
  EXPECT_NE(sink, 0.0);
}

}  // namespace
}  // namespace uh::forcecomp
