#pragma once
/// \file
/// ForceController: hands contact data from the collision thread to the haptic thread and turns it
/// into the device force every haptic tick (the paper's ForceController, section 3.2.5).

#include <atomic>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "uh/collette/collision_world.hpp"
#include "uh/controllers/contact_compliance.hpp"
#include "uh/controllers/tool_proxy.hpp"
#include "uh/controllers/workspace_mapping.hpp"
#include "uh/core/contact.hpp"
#include "uh/core/delegator.hpp"
#include "uh/core/latest_value.hpp"
#include "uh/forcecomp/contact_patches.hpp"
#include "uh/forcecomp/force_component.hpp"
#include "uh/forcecomp/force_safety.hpp"
#include "uh/forcecomp/held_contact_set.hpp"
#include "uh/forcecomp/material.hpp"
#include "uh/forcecomp/surface_stage.hpp"
#include "uh/forcecomp/virtual_coupling.hpp"
#include "uh/forcecomp/wrench_model.hpp"
#include "uh/haptico/haptic_manager.hpp"
#include "uh/scene/force_options.hpp"

namespace uh::controllers {

/// How a tick computes the force, and the controller's options: described by the scene
/// (uh/scene/force_options.hpp).
using uh::scene::ForceControllerOptions;
using uh::scene::TickForce;

/// What the controller did so far; a snapshot, plain data.
struct ForceControllerStats {
  std::uint64_t ticks = 0;            ///< force ticks run
  std::uint64_t contact_ticks = 0;    ///< ticks with at least one held pair of positive volume
  std::uint64_t frames_received = 0;  ///< contact frames taken over from the collision thread
  double max_force_n = 0.0;           ///< largest |force| it asked for [N], before the limit chain
  double max_torque_nm = 0.0;         ///< largest |torque| it asked for [N m], before the limit chain
  double max_force_step_n = 0.0;      ///< largest tick-to-tick change of the contact force before limits [N]
  double last_force_n = 0.0;          ///< |force| of the last tick [N]
  std::int32_t last_pairs = 0;        ///< pairs used in the last tick
  std::uint64_t model_clamped_ticks = 0;  ///< kModel: ticks beyond a model's trust range (clamped)
  std::uint64_t model_held_ticks = 0;     ///< kModel: ticks that held the last wrench (far beyond it)
  std::uint64_t model_checked_ticks = 0;  ///< check_model: ticks compared with the exact re-evaluation
  double model_error_rms_n = 0.0;         ///< check_model: RMS of |model force - exact force| [N]
  double model_error_max_n = 0.0;         ///< check_model: largest |model force - exact force| [N]
  forcecomp::ForceSafetyCounters safety{};
};

/// Binds OnCollision (collision thread) and ForceOnHapticTick (haptic thread).
///
/// On the collision thread, on_collision() builds each frame's wrench model per watched object
/// (TickForce::kModel; a frame of the tool against everything has a section per object) into a
/// lock-free LatestValue per watched object. On the haptic thread, on_force() takes the newest
/// model and renders it (WrenchModelRenderer), or (kExact, held forces, check_model) takes the
/// newest frame of each of its watchers straight from the world's handoff
/// (CollisionWorld::take_contact: the frame crosses threads once and is used where it lies, never
/// copied), holds each object's pairs and evaluates the volumetric penalty force and torque on the
/// tool (ForceComponent, its law), adds the friction and texture of each contact patch of pairs
/// with such a material (the patches' models travel with the model; for frames taken on the
/// haptic thread the patches are found there, once per frame), optionally through a virtual
/// coupling, applies ForceSafety (NaN guard, watchdog on the age of
/// the contact data) and adds the result, in the device frame, to the command; the manager's
/// limit chain bounds the sum.
///
/// Threads: construct, add_watched(), read_frames_of() and bind() on the controlling thread before
/// the threads start; the controller is then the reader of its watchers' frames (remove them from
/// the world only after it stopped); stats() from any thread. Its memory does not depend on the
/// pairs; the tick never allocates, locks, throws or logs.
class ForceController {
 public:
  ForceController(collette::ObjectId tool, const forcecomp::ForceComponent& tool_component,
                  const WorkspaceMapping& mapping, const ForceControllerOptions& options = {});
  ~ForceController();
  ForceController(const ForceController&) = delete;
  ForceController& operator=(const ForceController&) = delete;

  /// Takes forces from the watched pair (object, tool) of the world. `coverage_product` is the
  /// product of the object's and the tool's packing coverages (forcecomp::PenaltyInput), by which
  /// the gradient law is calibrated. `material` is the pair's combined material
  /// (forcecomp::combine_materials): its stiffness and damping replace the tool's for this pair,
  /// its friction and texture are rendered after the penalty wrench by a SurfaceStage per contact
  /// patch (forcecomp/contact_patches.hpp: each connected region of the overlap has its own stick
  /// point and normal force, so a tool pinched between two faces of the object rubs on both);
  /// without one, or without friction and texture, the pair feels as the tool's force parameters
  /// say and no patches are found. Controlling thread, before bind().
  void add_watched(collette::ObjectId object, double coverage_product = 1.0,
                   const forcecomp::ContactMaterial* material = nullptr,
                   const forcecomp::SurfaceStageOptions& surface = {});

  /// Takes the frames of this world watcher (a watched pair (object, tool) or the tool against
  /// everything) on the haptic thread, for kExact, held forces and check_model. Controlling
  /// thread, before bind().
  void read_frames_of(collette::WatcherId watcher) { watchers_.push_back(watcher); }

  /// Connects to the world's OnCollision and the manager's ForceOnHapticTick. The coupling's proxy
  /// is placed at the handle on the first tick. Controlling thread, before the threads start.
  void bind(collette::CollisionWorld& world, haptico::HapticManager& manager);
  /// Connects to the world's OnCollision only: the caller runs on_force() itself (a test, a host
  /// that steps the controller), whose tick time is then the device state's time_s.
  void bind(collette::CollisionWorld& world);

  /// OnCollision handler: collision thread; real-time safe.
  void on_collision(collette::ObjectId a, collette::ObjectId b, const ContactFrame& frame);
  /// ForceOnHapticTick handler: haptic thread; real-time safe.
  void on_force(const haptico::DeviceState& state, haptico::DeviceCommand& command);

  /// Renders the spring to this tool's proxy instead of penalty forces (the proxy outlives the
  /// controller's ticks). Controlling thread, before bind().
  void render_through(ToolProxy* proxy) { proxy_ = proxy; }
  /// The tool touches a soft object that gives way; `source` (its simulation's, read only by this
  /// tool's haptic thread) tells how far, so that between the object's steps the spring to the
  /// proxy, or on the penalty path the local model's stiffness along its force, is felt in series
  /// with its compliance (with_compliance). Controlling thread, before bind().
  void feel_compliance_of(LatestValue<ContactCompliance>* source) {
    compliances_.push_back(source);
    compliance_since_s_.push_back(0.0);
  }
  /// With a proxy: the proxy the last tick rendered against (slid towards the handle). Haptic thread.
  const Pose& rendered_proxy() const { return rendered_proxy_; }
  /// The coupling (null without one); the BridgingController reads its proxy pose.
  const forcecomp::VirtualCoupling* coupling() const { return options_.use_coupling ? &coupling_ : nullptr; }
  /// True once the coupling's proxy has been placed at the handle (haptic thread only).
  bool proxy_placed() const { return proxy_placed_; }
  /// Zero force from the next tick on (ForceSafety::stop). Any thread.
  void stop() { safety_.stop(); }
  ForceControllerStats stats() const;
  /// Pairs the force of the last tick used (ForceControllerStats::last_pairs), cheaply. Any thread.
  std::int32_t last_pairs() const { return last_pairs_.load(std::memory_order_relaxed); }
  const ForceControllerOptions& options() const { return options_; }

 private:
  bool uses_model() const { return options_.multi_rate && options_.tick_force == TickForce::kModel; }
  // A frame's models for the haptic thread (kModel): the pair's whole model, whose wrench is the
  // penalty felt, and, when the pair renders friction or texture, its contact patches' models
  // (forcecomp/contact_patches.hpp), whose wrenches split it into one normal force per patch.
  // Fixed-size plain data: it crosses in a LatestValue.
  struct FrameModels {
    forcecomp::WrenchModel whole;
    forcecomp::ContactPatches patches;  // count 0 without a surface stage or without contact
    forcecomp::WrenchModel patch_models[forcecomp::kMaxContactPatches];
  };
  // The friction and texture of one contact patch (haptic thread): its stick point lives as long
  // as the patch is found again, frame after frame, near the same point of the tool.
  struct PatchStage {
    bool live = false;                        // a patch of the held frame or model is rendered here
    std::int32_t index = 0;                   // which patch of the held frame or model
    double link = 0.0;                        // how far its point may move on the tool and stay it [m]
    forcecomp::SurfaceStage surface;          // friction and texture after the patch's penalty
    forcecomp::WrenchModelRenderer renderer;  // kModel: the patch's model
    forcecomp::Wrench held_wrench{};          // held-force mode: the patch's force at the frame
    Vec3 contact_point_tool{};                // the patch's contact point, tool frame [m]
    Vec3 contact_point_world_at_frame{};      // where that point was when the frame was queried [m]
    double depth_at_frame_m = 0.0;            // the patch's penetration estimate [m]
  };
  struct Watched {
    collette::ObjectId object = -1;
    double coverage_product = 1.0;        // c_object * c_tool
    forcecomp::ForceComponent component;  // the tool's, with the pair's material stiffness and damping
    bool has_surface = false;             // the material has friction or texture (else no patches)
    PatchStage stages[forcecomp::kMaxContactPatches];  // haptic thread, by stage, not by patch
    LatestValue<FrameModels> models;                   // collision thread -> haptic thread (kModel)
    bool modelled_contact = false;            // collision thread: the last model published had contact
    forcecomp::WrenchModelRenderer renderer;  // haptic thread
    forcecomp::HeldContactSet held;           // haptic thread: a view of the world's frame, its section
    forcecomp::ContactPatches held_patches;   // haptic thread: the held section's patches (with a surface)
    std::int32_t modelled_patches = 0;        // haptic thread: patches of the model taken last (kModel)
    bool in_frame = false;                    // haptic thread: scratch of taking a frame
    Pose world_from_object{};                 // object pose used by the held frame's query
    forcecomp::Wrench held_wrench{};          // force of the newest frame (held-force mode)
    std::int32_t held_pairs = 0;
    explicit Watched(const forcecomp::WrenchModelOptions& model) : renderer(model) {
      for (PatchStage& s : stages) s.renderer = forcecomp::WrenchModelRenderer(model);
    }
  };
  Watched* find_watched(collette::ObjectId object);
  // one tick's sums over the watched objects (penalty paths)
  struct TickSum {
    forcecomp::Wrench contact{};
    std::int32_t pairs = 0;
    double oldest_data_s = 0.0;  // the oldest collision data the force used [s]
    Vec3 exact_force{};          // check_model: the exact re-evaluation's force, beside the model's
    std::uint64_t clamped = 0;   // kModel: the renderers' clamped and held ticks
    std::uint64_t held = 0;
    double normal_stiffness = 0.0;  // kModel: the models' stiffness along their forces [N/L], for a soft object's compliance
  };
  double tick_period(double now);
  void take_model(Watched& w, const Pose& world_from_tool);
  void add_modelled(Watched& w, double now, const Pose& world_from_tool, const forcecomp::BodyMotion& tool_motion,
                    TickSum& sum);
  void add_held(Watched& w, const Pose& world_from_tool, const forcecomp::BodyMotion& tool_motion, TickSum& sum);
  void record_model_check(const TickSum& sum);
  // proxy mode: the spring between the handle and the proxy slid towards it; sets the data's time
  // and the constraints holding the proxy
  forcecomp::Wrench proxy_wrench(const Pose& world_from_handle_tool, double now, double& data_time_s,
                                 std::int32_t& holding);
  Vec3 with_compliance(const Vec3& spring_force, double spring, double now);
  static double stiffness_along(const forcecomp::WrenchModel& m, const Vec3& force);
  // the end of every tick: statistics, the safety stage, the device frame
  void finish_tick(const forcecomp::Wrench& contact, const forcecomp::Wrench& to_device, double now,
                   double oldest_data_s, std::int32_t pairs, haptico::DeviceCommand& command);
  void publish_model(Watched& w, const ContactFrame& frame, const ContactSection* section);
  void take_frame(const ContactFrame& frame, const Pose& world_from_tool,
                  const forcecomp::BodyMotion& tool_motion);

  collette::ObjectId tool_;
  bool renders_torque_ = true;  // the device actuates torque (bind() with a manager asks it)
  forcecomp::ForceComponent component_;
  WorkspaceMapping mapping_;
  ForceControllerOptions options_;
  forcecomp::ForceSafety safety_;
  forcecomp::VirtualCoupling coupling_;
  std::vector<std::unique_ptr<Watched>> watched_;
  std::vector<collette::WatcherId> watchers_;
  collette::CollisionWorld* world_ = nullptr;
  haptico::HapticManager* manager_ = nullptr;
  ScopedConnection collision_connection_;
  ScopedConnection force_connection_;

  ToolProxy* proxy_ = nullptr;
  ProxyState proxy_state_{};      // haptic thread: the newest proxy taken
  Pose rendered_proxy_{};         // haptic thread: it, slid towards the handle
  bool have_proxy_state_ = false;
  double contact_spring_n_m_ = 0.0;  // haptic thread: the last holding contact's ProxyContact::stiffness_n_m
  std::vector<LatestValue<ContactCompliance>*> compliances_;  // soft objects the proxy may rest on
  std::vector<double> compliance_since_s_;  // per source: the tick time its newest value came [s]

  // haptic thread state
  double last_tick_s_ = 0.0;
  bool have_last_tick_ = false;
  bool proxy_placed_ = false;
  Vec3 last_contact_force_{};

  // where a frame was found: the tool's and the object's poses, the overlap's volume centroid and
  // its gradient (of a patch, from a ContactFrame or a WrenchModel), and the patch's link distance
  struct FrameContact {
    Pose world_from_tool{};
    Pose world_from_object{};
    Vec3 volume_centroid_world{};
    Vec3 volume_gradient_world{};
    double total_volume = 0.0;
    double link = 0.0;
  };
  // the patches of a new frame or model take over the stages of the last one's (by where they
  // touch the tool), the others start new stick points or end
  void take_patches(Watched& w, std::span<const FrameContact> patches, const Pose& world_from_tool);
  void hold_contact_geometry(PatchStage& s, const FrameContact& frame, const Pose& world_from_tool);
  void end_patches(Watched& w);
  // the one place where materials come in: friction and texture of one patch on its penalty
  // wrench; returns what they add
  forcecomp::Wrench add_surface(const Watched& w, PatchStage& s, const forcecomp::Wrench& penalty,
                                const Pose& world_from_tool, const forcecomp::BodyMotion& tool_motion);

  // published to stats() readers
  std::atomic<std::uint64_t> ticks_{0};
  std::atomic<std::uint64_t> contact_ticks_{0};
  std::atomic<std::uint64_t> frames_received_{0};
  std::atomic<double> max_force_n_{0.0};
  std::atomic<double> max_torque_nm_{0.0};
  std::atomic<double> max_force_step_n_{0.0};
  std::atomic<double> last_force_n_{0.0};
  std::atomic<std::int32_t> last_pairs_{0};
  std::atomic<std::uint64_t> model_clamped_ticks_{0};
  std::atomic<std::uint64_t> model_held_ticks_{0};
  std::atomic<std::uint64_t> model_checked_ticks_{0};
  std::atomic<double> model_error_sum_sq_{0.0};
  std::atomic<double> model_error_max_n_{0.0};
};

}  // namespace uh::controllers
