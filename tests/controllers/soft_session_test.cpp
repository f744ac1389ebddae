// A soft block in a session (issue 26): scenes/soft_block.json's block, its base held, pressed by
// its 1 cm ball on a sim-line, in simulated time (run_stepped: the soft steps every 10 ticks).
// - the loads on the block's nodes sum to minus the force the ball felt (the tick before the
//   step), as the session's own published state says it;
// - the block gives: pressed deeper, the ball feels more force and the block's top goes down
//   more; a rigid block under the same press pushes back harder.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "scene_test_support.hpp"
#include "soft_block_support.hpp"
#include "uh/controllers/haptic_session.hpp"

namespace uh::controllers {
namespace {

using testing::soft_block;

struct Press {
  double force_n = 0.0;        // the ball's force at the end [N]
  double indentation_m = 0.0;  // the largest downward displacement of a node of the block [m]
};

Press press(double depth_m, bool soft = true) {
  SessionOptions options;
  options.cache_dir = testing::fresh_cache("soft-session");
  auto session = HapticSession::create(soft_block(depth_m, soft), options);
  EXPECT_TRUE(session.has_value()) << session.error().message;
  std::vector<Vec3> forces;
  auto seen = (*session)->on_haptic_tick().connect([&](const SessionState& s) { forces.push_back(s.force_world); });
  EXPECT_TRUE((*session)->run_stepped(1.0, 1).has_value());
  Press out;
  out.force_n = norm(forces.at(989));  // the run ends by sending zero: a tick before its end
  const SoftSimulation* sim = (*session)->soft_simulation(0);
  if (sim == nullptr) return out;
  const auto& rest = sim->body().mesh.nodes;
  for (std::size_t n = 0; n < rest.size(); ++n)
    out.indentation_m = std::max(out.indentation_m, rest[n].z() - sim->fem().positions()[n].z());
  // the report's record (uh run --plot): a sample per step, the last one this step's
  const auto& soft_report = (*session)->report().soft;
  EXPECT_EQ(soft_report.size(), 1u);
  if (!soft_report.empty()) {
    const auto& samples = soft_report.front().samples;
    EXPECT_EQ(samples.size(), 100u);  // 1 s at 100 Hz
    Eigen::Vector3d total = Eigen::Vector3d::Zero();
    for (const auto& l : sim->loads()) total += l;
    EXPECT_NEAR(samples.back().force_n, total.norm(), 1e-12);
    std::vector<float> xyz(3 * sim->body().surface.vertices.size());
    soft::deform_surface(sim->body(), sim->fem().positions(), xyz);
    double deepest = 0.0;
    for (std::size_t v = 0; v < sim->body().surface.vertices.size(); ++v)
      deepest = std::max(deepest, sim->body().surface.vertices[v].z() - double{xyz[3 * v + 2]});
    EXPECT_NEAR(samples.back().indentation_m, deepest, 1e-9);
  }
  // the last soft step (tick 990) spread what the ball felt on the tick before it
  Eigen::Vector3d loads = Eigen::Vector3d::Zero();
  for (const auto& l : sim->loads()) loads += l;
  const Vec3& felt = forces.at(989);
  EXPECT_GT(norm(felt), 0.1);
  EXPECT_LT((loads + Eigen::Vector3d(felt.x, felt.y, felt.z)).norm(), 1e-9 * (1.0 + norm(felt)))
      << "loads " << loads.transpose() << ", felt " << felt.x << " " << felt.y << " " << felt.z;
  return out;
}

TEST(SoftSession, TheBlockGivesUnderTheBallAndTakesWhatTheBallFelt) {
  const Press shallow = press(0.002);
  const Press deep = press(0.004);
  const Press rigid = press(0.004, false);
  RecordProperty("force_shallow_n", std::to_string(shallow.force_n));
  RecordProperty("force_deep_n", std::to_string(deep.force_n));
  RecordProperty("indentation_shallow_m", std::to_string(shallow.indentation_m));
  RecordProperty("indentation_deep_m", std::to_string(deep.indentation_m));
  EXPECT_GT(shallow.force_n, 0.2);
  EXPECT_GT(deep.force_n, shallow.force_n * 1.2);
  EXPECT_GT(shallow.indentation_m, 1e-4);
  EXPECT_GT(deep.indentation_m, shallow.indentation_m * 1.2);
  // the same press on a rigid block: the ball goes deeper into the spheres, and feels more
  EXPECT_GT(rigid.force_n, deep.force_n * 1.05);
  std::printf("shallow %.3f N %.3f mm, deep %.3f N %.3f mm, rigid %.3f N\n", shallow.force_n,
              shallow.indentation_m * 1e3, deep.force_n, deep.indentation_m * 1e3, rigid.force_n);
}

}  // namespace
}  // namespace uh::controllers
