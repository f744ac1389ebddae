#pragma once
/// \file
/// SoftSimulation: one deformable object of a session (issue 26; docs/deformables.md, "In a
/// session"). Three kinds of thread meet here, each through its own lock-free handoff:
///  - the simulation thread (step(), at a fixed rate): takes the newest contacts and tool
///    forces, turns them into nodal loads, steps the FEM, moves the packing's spheres with their
///    tetrahedra and refits a copy of the tree (or rebuilds it when the refit has grown too
///    loose: SoftTreeOptions), which it publishes (LatestValue: the newest wins);
///  - the collision thread queries the newest published tree (CollisionObjectDef::deformed_trees)
///    and posts the object's pairs of each tool's frame (post_contacts; a proxy's, weighed where
///    the proxy moved to after its step: rest_proxy_at);
///  - each tool's haptic thread posts the force its tool felt (post_tool_force);
///  - each step's compliance at a proxy's contact goes beside the tree it publishes, and the
///    collision thread hands the compliance of the tree it took to the tool's haptic thread once
///    the proxy rests on that tree (rest_proxy_at, compliance).
/// The haptic thread never waits on the simulation: it only writes into its own triple buffer.

#include <Eigen/Core>

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <span>
#include <vector>

#include "uh/collette/sphere_tree.hpp"
#include "uh/collette/sphere_tree_builder.hpp"
#include "uh/controllers/contact_compliance.hpp"
#include "uh/core/background_worker.hpp"
#include "uh/core/contact.hpp"
#include "uh/core/fixed_rate_loop.hpp"
#include "uh/core/latest_value.hpp"
#include "uh/core/math.hpp"
#include "uh/core/result.hpp"
#include "uh/soft/corotational_fem.hpp"
#include "uh/soft/soft_body.hpp"

namespace uh::controllers {

/// The contact spheres of one tool on the object, as the collision thread last saw them.
struct SoftContacts {
  /// The most spheres a frame hands over; more are dropped (the weights of the rest still sum to 1).
  static constexpr std::int32_t kCapacity = 4096;
  std::int32_t count = 0;
  /// This object's share of the tool's contact (its section's volume over the frame's), [0, 1].
  double share = 0.0;
  std::array<std::int32_t, kCapacity> leaves{};  ///< the object's leaf spheres in contact
  /// each pair's weight: its overlap volume, or through a proxy its nearness (rest_on_proxy)
  std::array<float, kCapacity> weights{};
  /// the pairs' weighted mean normal, pushing the tool out of the object [unit, world]; zero: none
  Vec3 normal_world{};
};

/// The drawn surface's deformed vertices as one step left them.
struct SoftSurface {
  std::vector<float> xyz;  ///< x, y, z per vertex of the body's surface [m, object frame]
  std::uint64_t step = 0;  ///< the step that made them (1, 2, ...)
};

/// One step of a soft object as `uh run --plot` draws it: how deep it was pressed and how hard.
struct SoftSample {
  double time_s = 0.0;         ///< the simulation's time at the step's end [s]
  double indentation_m = 0.0;  ///< the deepest downward (world -z) displacement of a surface vertex [m]
  double force_n = 0.0;        ///< |sum of the step's loads|: what the tools pressed it with [N]
  double tree_distortion = 1.0;  ///< the step's tree distortion (SoftSimulation::tree_distortion)
};

/// How a soft object's tree follows its deformation (docs/deformables.md, "The packing rides
/// along").
struct SoftTreeOptions {
  /// The default of rebuild_distortion: scenes/soft_block.json's presses (the ball 2 and 4 mm into
  /// the block, the reacting hand's presses) keep the distortion at or below 1 (a dent shrinks its
  /// spheres); its block sheared until its top has moved about its height (19 mm) reaches 1.45
  /// refitted only (tests/controllers/soft_tree_rebuild_test.cpp).
  static constexpr double kRebuildDistortion = 1.3;
  /// Each step refits the tree; when the refitted tree's looseness (the volume of its node spheres
  /// just above the leaves, SphereTree::leaf_parent_volume, over the object's volume) exceeds this
  /// many times that of its hierarchy refitted where it was built (at rest, or at the last
  /// rebuild), the step rebuilds the hierarchy over the deformed spheres instead
  /// (collette::rebuild_sphere_tree, with the rest tree's arity). > 1; infinity: never.
  double rebuild_distortion = kRebuildDistortion;
  /// The most of the simulation thread's time that rebuilds may take, in (0, 1]: after a rebuild
  /// that took T, the next waits until T (1 / share - 1) has passed (a body crushed until its
  /// elements invert loosens a fresh tree within a step, and a rebuild costs tens of steps at
  /// 10,000 spheres).
  double rebuild_time_share = 0.1;
};

class SoftSimulation {
 public:
  /// The simulation of `body` (its rest model) whose rest tree is `rest_tree`, placed with
  /// `world_from_object`, touched by `tools` tools. Fails when the FEM cannot be built, the tree
  /// cannot be refitted or `tree_options` are out of range. Setup only.
  static Result<std::unique_ptr<SoftSimulation>> create(std::shared_ptr<const soft::SoftBodyModel> body,
                                                        std::shared_ptr<const collette::SphereTree> rest_tree,
                                                        const Pose& world_from_object, std::size_t tools,
                                                        const SoftTreeOptions& tree_options = {});

  ~SoftSimulation();  // stops the thread and the workers

  /// The trees the collision thread queries (its only reader).
  LatestValue<collette::SphereTree>& trees() { return trees_; }

  /// Tool `tool` is a proxy (ToolProxy), which rests on the object's spheres within the margin
  /// rather than in them, so its pairs have no overlap volume: each pair is weighed by its nearness
  /// instead, exp(-(gap - smallest gap) / `smoothing_m`), the share of the proxy's soft-minimum row
  /// (forcecomp: the soft minimum's gradient) that the pair takes, at the pose the proxy moved to
  /// (rest_proxy_at). Setup only, before the threads (it sizes the tool's pair buffer).
  void rest_on_proxy(std::size_t tool, double smoothing_m);

  /// Collision thread: the pairs of `frame`'s that touch this object (object `object`, on side A
  /// of a pair as the session watches it) become tool `tool`'s newest contacts; a frame of another
  /// object's watcher is ignored. A tool-against-everything frame gives the object's share of the
  /// tool's contact (of its pairs' weights); a frame of this object alone gives it all of the
  /// tool's force. A proxy's pairs are kept until rest_proxy_at weighs them. Real-time safe.
  void post_contacts(std::size_t tool, std::int32_t object, const ContactFrame& frame);
  /// Controlling thread: the object now stands at `world_from_object` (HapticSession::set_object_pose);
  /// the next step turns the world's loads into the object's frame with it (the simulation, its
  /// tree and surface stay in the object's own frame). Real-time safe.
  void set_pose(const Pose& world_from_object) { rotation_in_.write(world_from_object.rotation); }
  /// Collision thread, after proxy tool `tool` (rest_on_proxy) has stepped to `world_from_proxy`
  /// on the tree the collision step took (trees()): the pairs of its last frame (post_contacts),
  /// weighed by their nearness at that pose, become its newest contacts (nothing when no frame came
  /// since the last call), and the compliance of the step that published that tree goes to the
  /// tool's haptic thread (compliance()). The frame was queried where the proxy was before its
  /// step, while the force the tool feels until the next step is the spring to where it is now:
  /// weighed at the old pose, the object would take the force a collision step behind where the
  /// tool presses it; and the newest step's compliance describes a surface the proxy does not rest
  /// on yet (docs/deformables.md, "What the hand feels"). Real-time safe.
  void rest_proxy_at(std::size_t tool, const Pose& world_from_proxy);
  /// Collision thread, after its step: the compliance of the step that published the tree the
  /// collision step took goes to tool `tool`'s haptic thread (compliance()), once per step, so
  /// that the haptic thread feels the step whose surface its contact is on (a proxy's rest_proxy_at
  /// does this; a penalty tool's model is built from that tree). Real-time safe.
  void hand_over_compliance(std::size_t tool);
  /// Haptic thread of `tool`: the force [N, world] its tool felt this tick. Real-time safe.
  void post_tool_force(std::size_t tool, const Vec3& force_world);
  /// What a step tells tool `tool`'s haptic thread (its only reader) of the contact: the force the
  /// step took and the object's compliance there (ForceController::feel_compliance_of), handed
  /// over with the tree the tool's contact is on (hand_over_compliance).
  LatestValue<ContactCompliance>& compliance(std::size_t tool) { return *compliances_[tool]; }

  /// Vertices of the body's drawn surface (SoftBodyModel::surface).
  std::size_t surface_vertex_count() const { return body_->surface.vertices.size(); }
  /// Copies the newest published deformed surface into `xyz` (3 floats per vertex, as many as
  /// fit; the rest pose before the first step) and returns the step that made it (0: at rest).
  /// Any thread but the simulation's; readers take turns (a lock among readers: the simulation
  /// thread never takes it, so it never waits).
  std::uint64_t read_surface(std::span<float> xyz);

  /// Simulation thread: one step of `dt_s` under the newest contacts; publishes the refitted (or
  /// rebuilt) tree and the deformed surface.
  Status step(double dt_s);

  /// With `on`, a rebuild of the tree (SoftTreeOptions) runs on a worker thread while the steps go
  /// on refitting the older hierarchy, and the steps after it take the rebuilt one: a step never
  /// stops for it (174 ms at 10,000 spheres, 35 steps at 200 Hz). Off (the default), a step rebuilds
  /// in place. start() turns it on. Also gives the FEM's factorisations to a worker and its element
  /// pass to a second thread (CorotationalFem::factorise_in_background, assemble_on_two_threads).
  /// Controlling thread, while no step runs.
  void work_in_background(bool on);

  /// Runs step() at `rate_hz` on its own thread until stop(), working in the background. A step
  /// that fails ends the thread; `on_failure` is called on it first (the session zeroes every
  /// device's force there: the object would otherwise stand frozen under the tool). Controlling
  /// thread.
  Status start(double rate_hz, std::function<void()> on_failure = {});
  void stop();
  /// Fault injection, for tests of what a failed step does (a failed solve is hard to cause on
  /// purpose): the next step fails as a failed solve would. Any thread; real-time safe.
  void fail_next_step() { fail_next_step_.store(true, std::memory_order_relaxed); }
  /// Whether the simulation thread runs (true before start()): a failed step ends it.
  bool running() const { return !loop_ || loop_->running(); }
  /// The simulation thread's failure (a step that failed ends the thread), once it stopped.
  Status failure() const { return failure_; }
  FixedRateLoopStats stats() const { return loop_ ? loop_->stats() : FixedRateLoopStats{}; }

  /// The last step's nodal loads [N, object frame]. Simulation thread (or after stop()).
  const std::vector<Eigen::Vector3d>& loads() const { return loads_; }
  /// The last step's deformed leaf spheres [m, object frame]. Simulation thread (or after stop()).
  std::span<const Sphere> spheres() const { return spheres_; }
  /// A sample per step (the first kRecordCapacity; allocated at create()). Simulation thread (or
  /// after stop()).
  const std::vector<SoftSample>& record() const { return record_; }
  static constexpr std::size_t kRecordCapacity = 60000;  // five minutes at 200 Hz
  /// How many steps late the simulation thread may fall before it skips steps (FixedRateLoopOptions::catch_up_periods).
  static constexpr int kCatchUpSteps = 20;
  /// Steps taken so far. Simulation thread (or after stop()).
  std::uint64_t steps() const { return steps_; }
  /// The last step's tree distortion (SoftTreeOptions::rebuild_distortion): 1 at rest, a little
  /// under 1 right after a rebuild (the builder's spheres are tighter than a refit's). Simulation
  /// thread (or after stop()).
  double tree_distortion() const { return tree_distortion_; }
  /// How many steps rebuilt the tree. Simulation thread (or after stop()).
  std::uint64_t tree_rebuilds() const { return tree_rebuilds_; }
  const soft::CorotationalFem& fem() const { return fem_; }
  const soft::SoftBodyModel& body() const { return *body_; }

 private:
  SoftSimulation(std::shared_ptr<const soft::SoftBodyModel> body, std::shared_ptr<const collette::SphereTree> rest_tree,
                 soft::CorotationalFem fem, const Pose& world_from_object, std::size_t tools,
                 const SoftTreeOptions& tree_options);
  void gather_loads();
  Status refit_or_rebuild(collette::SphereTree& slot);
  Status rebuild_in_place(collette::SphereTree& slot);
  Status take_rebuilt_hierarchy();
  void adopt_hierarchy(std::chrono::steady_clock::duration took);
  std::uint64_t& hierarchy_of(const collette::SphereTree& slot);
  double looseness(const collette::SphereTree& tree) const;
  bool spread_tool_force(std::size_t tool, const Vec3& force_world, std::vector<Eigen::Vector3d>& loads) const;
  Status find_compliances(double dt_s);
  // A pair of a proxy tool's frame, kept by post_contacts until rest_proxy_at weighs it.
  struct ProxyPair {
    Vec3 object_centre_world{};  // the object's sphere at the query's pose [m, world]
    Vec3 tool_centre_local{};    // the tool's sphere [m, tool frame]
    double radii = 0.0;          // the two spheres' radii [m]
    std::int32_t leaf = -1;      // the object's leaf (this object's pairs)
    bool this_object = false;    // false: another object's pair, which counts in the share only
    double gap = 0.0;            // scratch of weigh_by_nearness [m]
  };
  struct ProxyPairs {
    bool posted = false;          // a frame came since the last rest_proxy_at
    std::vector<ProxyPair> pairs;  // capacity kProxyPairCapacity (rest_on_proxy), never grown
  };
  // a frame's pairs past this many are left out (a tool's pairs within the margin: tens to hundreds)
  static constexpr std::size_t kProxyPairCapacity = SoftContacts::kCapacity;
  void keep_proxy_pairs(std::int32_t object, const ContactFrame& frame, ProxyPairs& out) const;
  void weigh_by_nearness(double smoothing_m, ProxyPairs& frame, const Pose& world_from_proxy, SoftContacts& out) const;
  void publish_surface(double dt_s);
  void record_step(double dt_s, std::span<const float> xyz);

  std::shared_ptr<const soft::SoftBodyModel> body_;
  std::shared_ptr<const collette::SphereTree> rest_tree_;
  soft::CorotationalFem fem_;
  Quat object_from_world_;
  LatestValue<Quat> rotation_in_;  // controlling thread -> simulation: world_from_object's newest rotation
  LatestValue<collette::SphereTree> trees_;
  // The current hierarchy (the rest tree's until a rebuild) and its generation; each slot of trees_
  // keeps the generation it holds (by address: a triple buffer has three), and one holding an
  // older one takes a copy of this before its refit.
  SoftTreeOptions tree_options_;
  collette::SphereTreeBuildOptions rebuild_options_;
  collette::SphereTree hierarchy_;
  std::uint64_t hierarchy_generation_ = 1;
  struct SlotHierarchy {
    const collette::SphereTree* slot = nullptr;
    std::uint64_t generation = 0;  // 0: none yet
  };
  std::array<SlotHierarchy, 3> slot_hierarchies_{};
  std::uint64_t unknown_slot_generation_ = 0;
  double hierarchy_looseness_ = 1.0;  // the looseness of hierarchy_ when it was built
  double tree_distortion_ = 1.0;
  std::uint64_t tree_rebuilds_ = 0;
  std::chrono::steady_clock::time_point next_rebuild_{};  // none before (rebuild_time_share)
  struct BackgroundRebuild;  // the worker's tree and how its rebuild went
  std::unique_ptr<BackgroundRebuild> background_rebuild_;  // with work_in_background
  LatestValue<SoftSurface> surfaces_;  // simulation -> readers of the drawn surface
  std::mutex surface_readers_;         // one reader of surfaces_ at a time
  std::uint64_t steps_ = 0;
  std::vector<std::unique_ptr<LatestValue<SoftContacts>>> contacts_;  // per tool: collision -> simulation
  std::vector<std::unique_ptr<LatestValue<Vec3>>> tool_forces_;       // per tool: haptic -> simulation
  std::vector<double> proxy_smoothing_m_;  // per tool: 0 weighs pairs by overlap, > 0 by nearness
  std::vector<ProxyPairs> proxy_pairs_;    // per tool: collision thread, a proxy's last frame's pairs
  // per slot of trees_ (its read_slot / write_slot), per tool: the compliance of the step that
  // filled the slot, owned as the slot is (simulation thread, then the collision thread)
  std::array<std::vector<ContactCompliance>, 3> tree_compliances_;
  std::vector<std::uint64_t> compliance_step_sent_;  // per tool: collision thread, the last handed over
  std::vector<std::unique_ptr<LatestValue<ContactCompliance>>> compliances_;  // per tool: collision -> haptic
  std::vector<Eigen::Vector3d> loads_;
  std::vector<Eigen::Vector3d> unit_loads_, unit_moves_;  // scratch of find_compliances
  std::vector<Sphere> spheres_;
  Vec3 down_in_object_;  // the world's -z in the object's frame
  std::vector<SoftSample> record_;
  std::unique_ptr<FixedRateLoop> loop_;  // made by start()
  Status failure_ = Ok{};
  std::atomic<bool> fail_next_step_{false};
};

}  // namespace uh::controllers
