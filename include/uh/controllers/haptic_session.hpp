#pragma once
/// \file
/// HapticSession: a whole scene running: the device and haptic thread (Haptico), the collision
/// world and its thread (Collette), the controllers and forces (ForceComp), and a monitor thread
/// that records them. The owner starts it, reads its newest state and contact events while it
/// runs, and stops it. What `uh run`, the C API and the Python module run.

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <ostream>
#include <string>
#include <thread>
#include <vector>

#include "uh/collette/collision_world.hpp"
#include "uh/controllers/bridging_controller.hpp"
#include "uh/controllers/force_controller.hpp"
#include "uh/controllers/scene.hpp"
#include "uh/controllers/session_model.hpp"
#include "uh/controllers/soft_simulation.hpp"
#include <span>
#include "uh/core/delegator.hpp"
#include "uh/core/event_counter.hpp"
#include "uh/core/latest_value.hpp"
#include "uh/core/result.hpp"
#include "uh/core/spsc_queue.hpp"
#include "uh/devices/hardware_drivers.hpp"
#include "uh/haptico/device_registry.hpp"
#include "uh/haptico/haptic_manager.hpp"

namespace uh::controllers {

/// What a session of a compiled model does beyond its model (aggregate).
struct SessionRunOptions {
  bool raise_priority = false;  ///< ask for SCHED_FIFO for the haptic (80) and collision (70) threads
};

/// Overrides of the scene for one session (aggregate; unset fields keep the scene's value).
struct SessionOptions {
  std::optional<double> haptic_hz;       ///< haptic rate [Hz]
  std::optional<double> collision_hz;    ///< collision rate [Hz]; 0 = free-running
  std::optional<bool> multi_rate;        ///< follow the tool between frames (else hold forces)
  std::optional<TickForce> tick_force;   ///< the multi-rate tick's wrench: the frame's model or every pair
  /// Render through the 6-DOF proxy (true; the scene's force.coupling is then left out) or the
  /// penalty path (false), whatever the scene's force.proxy says.
  std::optional<bool> proxy;
  bool check_model = false;              ///< also run the exact re-evaluation and record the model's error
  std::optional<double> contact_margin;  ///< pairs delivered this far [m] before they touch
  std::optional<double> coherence_skin;  ///< volume-query coherence skin [m] (0 = off); default: the scene's
  bool raise_priority = false;           ///< ask for SCHED_FIFO for the haptic (80) and collision (70) threads
  std::filesystem::path cache_dir;       ///< where .ist builds are cached; empty = default_cache_dir()
  /// Build progress (what, fraction) while a mesh is packed on first use; calling thread.
  std::function<void(const std::string& what, double fraction)> build_progress;
};

/// A point of the session's timeline (for plots): haptic-rate samples of the force sent.
struct TimelineSample {
  double time_s = 0.0;       ///< since the session started [s]
  double force_n = 0.0;      ///< |force| sent to the device [N]
  double torque_nm = 0.0;    ///< |torque| sent [N m]
};

/// Collision rate over one window of the session.
struct RateSample {
  double time_s = 0.0;   ///< end of the window, since the session started [s]
  double rate_hz = 0.0;  ///< collision steps per second in the window [Hz]
};

/// The device a session ran on (plain data).
struct DeviceReport {
  std::string driver;  ///< registry name, e.g. "forcedimension"
  std::string name;    ///< DeviceInfo::name, e.g. "forcedimension omega.3"
  std::string model;   ///< as the device reports it ("" for simulated devices)
  std::string serial;  ///< "" when it has none
  double max_force_n = 0.0;
  /// The vendor's measured communication rate [Hz] where it reports one (forcedimension:
  /// dhdGetComFreq), else 0.
  double com_rate_hz = 0.0;
};

/// One tool's part of a run: its device, its haptic loop and the forces sent to its device.
/// Plain data.
struct ToolReport {
  std::string tool;  ///< SceneTool::name
  DeviceReport device{};
  // haptic thread (the tool's device's loop)
  double haptic_target_hz = 0.0;
  double haptic_rate_hz = 0.0;
  std::uint64_t haptic_ticks = 0;
  std::uint64_t haptic_missed_deadlines = 0;
  double jitter_p50_us = 0.0, jitter_p99_us = 0.0, jitter_p999_us = 0.0, jitter_max_us = 0.0;
  double tick_p50_us = 0.0, tick_p99_us = 0.0, tick_max_us = 0.0;  ///< haptic callback duration
  bool haptic_priority_raised = false;
  // forces
  double force_max_n = 0.0, torque_max_nm = 0.0;  ///< largest |force|, |torque| sent to the device [N], [N m]
  double force_max_step_n = 0.0;       ///< largest tick-to-tick change of the force sent to the device [N]
  double force_max_raw_step_n = 0.0;   ///< same for the contact force before coupling, limits and fades [N]
  std::uint64_t force_nonfinite = 0, force_clamped = 0, torque_clamped = 0, stale_ticks = 0;
  haptico::LimitCounters limits{};     ///< ticks in which each limit of the chain engaged
  std::uint64_t zeroed_ticks = 0;      ///< ticks sent zero by a halt or a fault (this device's or another's)
  std::uint64_t contact_ticks = 0;
  /// Energy the device's motors put into the hand [J]: per tick, the force sent (held over the
  /// period) times the handle's displacement until the next tick; exact for a zero-order hold.
  double work_on_hand_j = 0.0;
  /// The sum over the ticks that held a force of |displacement|^2 / period [m^2/s], at most the
  /// integral of the handle's squared speed while in contact: a device whose mechanism has the
  /// damping b dissipates at least b times this meanwhile. Colgate's passivity (a sampled spring is
  /// passive with the device's damping when b > K T / 2) is work_on_hand_j - b *
  /// contact_squared_speed_integral <= 0 over a closed path: the energy that reaches the hand
  /// through the handle (the zero-order hold's gain is at most K T / 2 times this).
  double contact_squared_speed_integral = 0.0;
  bool multi_rate = true;
  std::string tick_force = "model";                             ///< "model" or "exact" (with multi_rate)
  std::uint64_t model_clamped_ticks = 0, model_held_ticks = 0;  ///< ForceControllerStats
  std::uint64_t model_checked_ticks = 0;
  double model_error_rms_n = 0.0, model_error_max_n = 0.0;  ///< with check_model
  bool coupling = false;
  /// The god-object (ForceControllerOptions::proxy): whether it rendered, and ToolProxyStats.
  bool proxy = false;
  ToolProxyStats proxy_stats{};
  Vec3 proxy_position{};  ///< where the proxy ended [m, world frame]
  Quat proxy_rotation{};  ///< how it was turned then (world frame)
  std::vector<TimelineSample> timeline;
};

/// What `uh run --json` prints, and more. Plain data. Its ToolReport part is the first tool's
/// (the only one in one-tool scenes); `tools` has every tool's, the first included.
struct SessionReport : ToolReport {
  std::string scene;
  bool stepped = false;
  double seconds = 0.0;        ///< the time run [s] (less than asked when stopped early)
  bool stopped_early = false;  ///< request_stop() ended run() or run_stepped() before its time
  // collision thread
  double collision_target_hz = 0.0;
  double collision_rate_min_hz = 0.0, collision_rate_median_hz = 0.0, collision_rate_mean_hz = 0.0;
  std::uint64_t collision_steps = 0;
  double query_median_us = 0.0, query_p99_us = 0.0, query_max_us = 0.0;
  /// duration of a whole collision step (every watcher) [us]
  double step_median_us = 0.0, step_p99_us = 0.0, step_max_us = 0.0;
  std::int32_t objects = 0;      ///< objects in the collision world (the tools included)
  std::int64_t frame_bytes = 0;  ///< heap bytes of the watchers' contact frames at the end of the run
  std::int64_t max_pairs = 0;
  std::uint64_t truncated_frames = 0;
  std::uint64_t coherent_queries = 0;  ///< collision queries that reused their kept candidates
  std::vector<RateSample> collision_rates;
  std::vector<ToolReport> tools;  ///< per tool, in Scene::tools order
  /// Per soft object (scene order): its simulation thread's rate and a sample per step (its
  /// indentation and force).
  struct SoftObjectReport {
    std::string object;
    std::int64_t tetrahedra = 0;
    double target_hz = 0.0;  ///< the scene's deformable.rate_hz
    /// steps a second of wall time (FixedRateLoopStats::achieved_rate_hz); 0 in a stepped run
    double rate_hz = 0.0;
    std::uint64_t steps = 0;
    std::uint64_t missed_deadlines = 0;  ///< steps that started more than a period late
    double step_p50_ms = 0.0, step_p99_ms = 0.0, step_max_ms = 0.0;  ///< a step's wall time; 0 stepped
    std::vector<SoftSample> samples;
  };
  std::vector<SoftObjectReport> soft;
};

/// The newest state of one tool of a session, as its haptic thread sent it in its last tick (plain
/// data).
struct SessionState {
  std::int32_t tool = 0;               ///< the tool's index in Scene::tools
  double time_s = 0.0;                 ///< that tick's time since start() [s] (stepped: simulated time)
  Vec3 tool_position_world{};          ///< origin of the tool's mesh frame in the world [m] (the proxy's, with one)
  Quat tool_orientation_world{};       ///< the tool's orientation in the world (unit quaternion)
  Vec3 handle_position_world{};        ///< where the device's handle puts that origin [m] (the tool's, without a proxy)
  Vec3 force_world{};                  ///< force sent to the device, in the world frame [N]
  Vec3 torque_world{};                 ///< torque sent to the device, in the world frame [N m]
  std::int32_t contact_pairs = 0;      ///< sphere pairs the force of that tick used
  std::uint64_t haptic_ticks = 0;      ///< the tool's haptic ticks since start()
  std::uint64_t missed_deadlines = 0;  ///< the tool's haptic ticks that started more than a period late
  double haptic_rate_hz = 0.0;         ///< the tool's haptic ticks per second over the last ~100 ms [Hz]
  double collision_rate_hz = 0.0;      ///< collision steps per second over the last ~100 ms [Hz]
  std::uint32_t buttons = 0;           ///< the device's buttons as read that tick (bit i: button i)
};

/// Whether a contact began or ended.
enum class ContactEventKind : std::uint8_t {
  kBegin,  ///< the tool started to overlap the object (positive overlap volume; through the proxy,
           ///< which rests on the surface: its constraint rows with the object came into contact)
  kEnd,    ///< the overlap ended
};

/// A contact between a tool and a watched object began or ended (plain data).
struct ContactEvent {
  ContactEventKind kind = ContactEventKind::kBegin;
  std::int32_t object = -1;  ///< index of the object in Scene::objects
  std::int32_t tool = 0;     ///< index of the tool in Scene::tools
  double time_s = 0.0;       ///< time of the collision step that saw it, since start() [s]
  double volume = 0.0;       ///< overlap volume of that step [m^3] (0 for kEnd; 0 through the proxy)
  std::int32_t pairs = 0;    ///< overlapping sphere pairs of that step (0 for kEnd; through the proxy,
                             ///< its constraint rows in contact)
};

/// The scene as a session runs it: the options' rates, margins and force options over the scene's
/// (compile() then checks it as every scene is checked). For a caller that compiles a model itself.
Scene with_session_options(const Scene& scene, const SessionOptions& options);

class HapticSession {
 public:
  /// compile() then create(model, ...): the scene with the options' overrides, its trees through
  /// a cache of `options.cache_dir`, for callers that create one session of a scene.
  static Result<std::unique_ptr<HapticSession>> create(
      const Scene& scene, const SessionOptions& options = {},
      const haptico::DeviceRegistry& registry = devices::all_drivers());
  /// A session of a compiled model (compile(), session_model.hpp), which it shares read-only: a
  /// program that creates many sessions of one scene compiles it once. Loads nothing: creates
  /// the collision world and opens each tool's device through the registry, without starting
  /// threads. Errors name the scene and the part. Each tool gets its own HapticManager (its own
  /// haptic loop, limit chain and device limits); the tools share the collision world and its
  /// thread, and one FaultGroup: a fault of any device zeroes every device's force.
  static Result<std::unique_ptr<HapticSession>> create(
      std::shared_ptr<const SessionModel> model, const SessionRunOptions& options = {},
      const haptico::DeviceRegistry& registry = devices::all_drivers());
  /// As above with devices the caller made: `devices[i]` drives the model's tools[i] (at most one
  /// per tool; a missing or null entry opens that tool's device through the registry). For a
  /// program that owns its device: a scripted hand (`uh explore`), a device opened elsewhere. The
  /// session opens them and owns them from then on.
  static Result<std::unique_ptr<HapticSession>> create(
      std::shared_ptr<const SessionModel> model, std::vector<std::unique_ptr<haptico::HapticDevice>> devices,
      const SessionRunOptions& options = {}, const haptico::DeviceRegistry& registry = devices::all_drivers());
  ~HapticSession();
  HapticSession(const HapticSession&) = delete;
  HapticSession& operator=(const HapticSession&) = delete;

  /// Starts the haptic threads (one per tool), the collision thread and a monitor thread, and
  /// returns. The monitor drains the haptic traces every 20 ms into the report's timelines (and
  /// the first tool's as CSV into `trace`, which must outlive stop()) and samples the rates every
  /// 100 ms. A session runs once: start()
  /// after a run is an error. Owner thread.
  Status start(std::ostream* trace = nullptr);

  /// The newest state of tool `tool` (see SessionState; the first tool by default); before its
  /// first tick, a zero state. `tool` must be below tool_count(). Any thread but the haptic and
  /// collision threads; never blocks them (they only publish through a LatestValue); concurrent
  /// callers are serialised among themselves.
  SessionState state(std::size_t tool = 0);
  /// The scene's tools (Scene::tools.size()), each with its own device.
  std::size_t tool_count() const { return rigs_.size(); }

  /// Takes the oldest contact event not yet taken; false when none is waiting. Events queue up
  /// (up to kEventCapacity; more are dropped and counted) from start() or run_stepped() on.
  /// One consumer thread at a time (the owner).
  bool poll_event(ContactEvent& out);
  static constexpr std::size_t kEventCapacity = 1024;
  /// Contact events dropped because nobody took them in time. Any thread.
  std::uint64_t dropped_events() const { return dropped_events_.load(); }

  /// Moves scene object `object` (its index in Scene::objects) to `world_from_object` [m]; the
  /// collision thread uses it from its next step. One thread per object (the owner); real-time safe.
  Status set_object_pose(std::int32_t object, const Pose& world_from_object);

  /// Binding side of OnHapticTick(const SessionState&) of tool `tool` (below tool_count()): each of
  /// its ticks' state as it is published, on its haptic thread (the calling thread in stepped
  /// runs). Delegates must be real-time safe. Bind before start(), from the owner thread.
  DelegateSink<const SessionState&> on_haptic_tick(std::size_t tool = 0);

  /// Binding side of tool `tool`'s ForceOnHapticTick(const DeviceState&, DeviceCommand&): a force
  /// added to the contact force in the device's frame (e.g. the museum station's home spring), on
  /// the haptic thread, summed before the tool's limit chain (every limit, the fade and halt() apply
  /// to it). Delegates must be real-time safe. Bind before start(), from the owner thread.
  DelegateSink<const haptico::DeviceState&, haptico::DeviceCommand&> force_on_haptic_tick(
      std::size_t tool = 0);

  /// Sends every device zero force from its next tick on, whatever the controllers ask, until
  /// resume() (which fades the forces back in). Any thread; real-time safe. The station holds its
  /// session here while the game server is away or the round is paused.
  void halt();
  void resume();

  /// Sends zero force at once, stops and joins all threads, and completes the report. Idempotent:
  /// later calls return what the first returned. An error says which thread ended on its own or
  /// what failed (the report is still complete). Without a start(), does nothing. Owner thread.
  Status stop();

  /// True from start() until stop(). Owner thread.
  bool running() const { return phase_ == Phase::kRunning; }
  /// While running: a haptic, the collision or a soft object's simulation thread ended by itself,
  /// or a device faulted; every device has been sent zero (or gets it at its next tick), and
  /// stop() returns the cause. A host that runs the session with start() polls this (run() does).
  /// Owner thread.
  bool ended_by_itself() const;

  /// start(), then calls `on_status` on this thread about every 250 ms for `seconds`, then stop().
  /// Ends early (within 20 ms) on request_stop() or when the session ended by itself
  /// (ended_by_itself(); stop() then returns the cause, e.g. what a tick threw). stop() also
  /// runs when `on_status` throws.
  Status run(double seconds, const std::function<void(const SessionState&)>& on_status = {},
             std::ostream* trace = nullptr);

  /// Runs deterministically on the calling thread without any other thread: haptic ticks at the
  /// haptic rate in simulated time, one collision step every `ticks_per_collision_step` ticks;
  /// ends early on request_stop(); ends with zero force sent and traced, like a threaded run.
  Status run_stepped(double seconds, int ticks_per_collision_step, std::ostream* trace = nullptr);

  /// Asks run() or run_stepped() to end early, as if its time were up (the report says
  /// stopped_early). Any thread, and async-signal-safe (one lock-free atomic store): `uh run`
  /// calls it from its SIGINT and SIGTERM handlers. It stays requested: a later run ends at once.
  void request_stop() { stop_requested_.store(true, std::memory_order_relaxed); }

  /// The report of the run (complete after stop() or run_stepped()).
  const SessionReport& report() const { return report_; }
  /// The scene the session runs (the model's: with the options' overrides when created from a scene).
  const Scene& scene() const { return model_->scene; }
  const SessionModel& model() const { return *model_; }
  const collette::CollisionWorld& world() const { return *world_; }
  /// Scene object `object`'s simulation when it is deformable, else null. While the session runs
  /// only the simulation's own thread may read its state; before start() and after stop(), anyone.
  const SoftSimulation* soft_simulation(std::size_t object) const {
    return object < soft_.size() ? soft_[object].get() : nullptr;
  }
  SoftSimulation* soft_simulation(std::size_t object) { return object < soft_.size() ? soft_[object].get() : nullptr; }
  /// Scene object `object`'s drawn surface at rest (its mesh refined, load_soft_surface): the
  /// triangles of the deformed vertices. An error naming the object when it is rigid or there is
  /// no such object.
  Result<const soft::SurfaceMesh*> soft_surface(std::size_t object) const;
  /// The vertices of that surface, as soft_surface().
  Result<std::size_t> soft_vertex_count(std::size_t object) const;
  /// Copies object `object`'s newest deformed surface into `xyz` (x, y, z floats per vertex, [m]
  /// in the object's frame, as its mesh is) and returns the step that made it (0: at rest). An
  /// error when the object is rigid or `xyz` holds fewer than 3 * soft_vertex_count() floats.
  /// Any thread but the simulation's, while the session runs or not; never makes the simulation,
  /// collision or haptic threads wait.
  Result<std::uint64_t> soft_vertices(std::size_t object, std::span<float> xyz);

 private:
  enum class Phase : std::uint8_t { kReady, kRunning, kStopped };
  struct ToolRig;  // one tool with its device, its loop, its controllers and its published state

  HapticSession();
  // create()'s stages: the world and the objects, then each tool (its device, its controllers)
  Status add_objects(const SessionRunOptions& options);
  Status add_tool(std::size_t tool, std::unique_ptr<haptico::HapticDevice> device, const SessionRunOptions& options,
                  const haptico::DeviceRegistry& registry);
  Result<std::unique_ptr<haptico::HapticDevice>> make_device(const ToolRig& rig,
                                                             const haptico::DeviceRegistry& registry) const;
  Status open_device(ToolRig& rig, std::unique_ptr<haptico::HapticDevice> given, const SessionRunOptions& options,
                     const haptico::DeviceRegistry& registry);
  Status wire_controllers(ToolRig& rig);
  Status begin_run();
  // the run's statistics into each tool's report (before the loops stop), then (after the last
  // trace is taken) the tools' reports into report_
  void collect_tool_report(ToolRig& rig, bool stepped);
  void collect_report(double seconds, bool stepped);
  void record_proxy_ends();
  void publish_report();
  void take_trace(ToolRig& rig, std::vector<haptico::TraceSample>& buffer, std::ostream* trace);
  void monitor();
  double soft_rate_hz(std::size_t object) const;  // the object's deformable.rate_hz
  SessionReport::SoftObjectReport soft_object_report(std::size_t object) const;
  void on_collision(collette::ObjectId a, collette::ObjectId b, const ContactFrame& frame);
  void on_step(double time_s);
  void contact_edge(ToolRig& rig, collette::ObjectId object, bool touching, double time_s, double volume,
                    std::int32_t pairs);
  bool any_fault() const;
  void stop_soft();
  void collect_soft_report();  // once the simulations stopped
  Status soft_error() const;
  bool haptic_threads_running() const;
  bool soft_threads_running() const;
  Status device_error() const;
  Status thread_error() const;
  std::string tool_label(std::int32_t tool) const;

  std::shared_ptr<const SessionModel> model_;
  double haptic_hz_ = 1000.0;
  double collision_hz_ = 1000.0;
  // per scene object, null when rigid; before world_: the trees it publishes outlive the collision thread
  std::vector<std::unique_ptr<SoftSimulation>> soft_;
  std::unique_ptr<collette::CollisionWorld> world_;
  haptico::FaultGroup fault_group_;  // before the rigs: their managers use it to the end
  std::vector<std::unique_ptr<ToolRig>> rigs_;
  SessionReport report_;
  ScopedConnection collision_connection_;
  ScopedConnection step_connection_;

  static_assert(std::atomic<bool>::is_always_lock_free, "request_stop() must be async-signal-safe");
  std::atomic<bool> stop_requested_{false};
  Phase phase_ = Phase::kReady;
  Status stopped_{Ok{}};    // what the first stop() returned
  double t0_s_ = 0.0;       // steady-clock time of start() (0 in stepped runs) [s]
  double started_s_ = 0.0;  // steady-clock time of start(), for the report's duration [s]

  std::mutex state_readers_;  // serialises state() callers; the haptic threads never take it
  std::atomic<double> collision_rate_hz_{0.0};  // monitor thread -> haptic threads

  // collision thread -> owner
  SpscQueue<ContactEvent> events_{kEventCapacity};
  EventCounter dropped_events_;
  std::vector<collette::ObjectId> object_ids_;  // per scene object

  std::ostream* trace_ = nullptr;  // written by the monitor thread while it runs, then by stop()
  // steady-clock time stop() zeroed the force [s]; owner -> monitor thread
  std::atomic<double> halted_at_s_{std::numeric_limits<double>::infinity()};
  // stop() sets monitor_stop_ and wakes the monitor from its 20 ms sleep. A plain condition
  // variable: std::jthread's stop token waits through std::stop_callback, which can hang for
  // good under Debian's mingw-w64 libstdc++ (uh/core/address_wait.hpp); the C API test did.
  std::mutex monitor_mutex_;
  std::condition_variable monitor_wake_;
  bool monitor_stop_ = false;  // guarded by monitor_mutex_
  std::thread monitor_thread_;
};

/// The report as the JSON object `uh run --json` prints (nested: device.*, haptic.*, collision.*,
/// force.*, contact.*, energy.*: the first tool's, and tools[]: each tool's tool, device.*,
/// haptic.*, force.*, contact.*, energy.*), without the timelines.
std::string session_report_json(const SessionReport& report);

}  // namespace uh::controllers
