#pragma once
/// \file
/// HapticSession: a whole scene running: the device and haptic thread (Haptico), the collision
/// world and its thread (Collette), the controllers and forces (ForceComp), and the application
/// thread that watches them. What `uh run` runs.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "uh/collette/collision_world.hpp"
#include "uh/controllers/bridging_controller.hpp"
#include "uh/controllers/force_controller.hpp"
#include "uh/controllers/scene.hpp"
#include "uh/core/result.hpp"
#include "uh/haptico/device_registry.hpp"
#include "uh/haptico/haptic_manager.hpp"

namespace uh::controllers {

/// Overrides of the scene for one session (aggregate; unset fields keep the scene's value).
struct SessionOptions {
  std::optional<double> haptic_hz;       ///< haptic rate [Hz]
  std::optional<double> collision_hz;    ///< collision rate [Hz]; 0 = free-running
  std::optional<bool> multi_rate;        ///< re-evaluate held pairs every tick (else hold forces)
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

/// What `uh run --json` prints, and more. Plain data.
struct SessionReport {
  std::string scene;
  bool stepped = false;
  double seconds = 0.0;
  // haptic thread
  double haptic_target_hz = 0.0;
  double haptic_rate_hz = 0.0;
  std::uint64_t haptic_ticks = 0;
  std::uint64_t haptic_missed_deadlines = 0;
  double jitter_p50_us = 0.0, jitter_p99_us = 0.0, jitter_p999_us = 0.0, jitter_max_us = 0.0;
  double tick_p99_us = 0.0, tick_max_us = 0.0;  ///< haptic callback duration
  bool haptic_priority_raised = false;
  // collision thread
  double collision_target_hz = 0.0;
  double collision_rate_min_hz = 0.0, collision_rate_median_hz = 0.0, collision_rate_mean_hz = 0.0;
  std::uint64_t collision_steps = 0;
  double query_median_us = 0.0, query_p99_us = 0.0, query_max_us = 0.0;
  std::int64_t max_pairs = 0;
  std::uint64_t truncated_frames = 0;
  std::uint64_t coherent_queries = 0;   ///< collision queries that reused their kept candidates
  // forces
  double force_max_n = 0.0, torque_max_nm = 0.0;
  double force_max_step_n = 0.0;       ///< largest tick-to-tick change of the force sent to the device [N]
  double force_max_raw_step_n = 0.0;   ///< same for the contact force before coupling, limits and fades [N]
  std::uint64_t force_nonfinite = 0, force_clamped = 0, torque_clamped = 0, stale_ticks = 0;
  std::uint64_t contact_ticks = 0;
  double work_on_hand_j = 0.0;         ///< energy the device put into the hand [J]
  bool multi_rate = true;
  bool coupling = false;
  std::vector<TimelineSample> timeline;
  std::vector<RateSample> collision_rates;
};

/// Live figures for a status line, sampled by the application thread.
struct LiveStatus {
  double time_s = 0.0;
  double haptic_rate_hz = 0.0;
  double collision_rate_hz = 0.0;
  double force_n = 0.0;
  std::int32_t pairs = 0;
};

class HapticSession {
 public:
  /// Builds everything a scene needs (loads or builds the sphere trees, creates and opens the
  /// device through the registry), without starting threads. Errors name the scene and the part.
  static Result<std::unique_ptr<HapticSession>> create(const Scene& scene, const SessionOptions& options = {},
                                                       const haptico::DeviceRegistry& registry =
                                                           haptico::DeviceRegistry::with_simulated_devices());
  ~HapticSession();
  HapticSession(const HapticSession&) = delete;
  HapticSession& operator=(const HapticSession&) = delete;

  /// Runs the three threads for `seconds`: haptic, collision, and this (application) thread, which
  /// samples statistics every 20 ms, calls `on_status` about every 250 ms, and writes the trace
  /// CSV to `trace` if given. Stops both threads and zeroes the force at the end.
  Status run(double seconds, const std::function<void(const LiveStatus&)>& on_status = {},
             std::ostream* trace = nullptr);

  /// Runs deterministically on the calling thread without any other thread: haptic ticks at the
  /// haptic rate in simulated time, one collision step every `ticks_per_collision_step` ticks.
  Status run_stepped(double seconds, int ticks_per_collision_step, std::ostream* trace = nullptr);

  const SessionReport& report() const { return report_; }
  const Scene& scene() const { return scene_; }
  const collette::CollisionWorld& world() const { return *world_; }

 private:
  HapticSession() = default;
  void begin_run();
  void collect_report(double seconds, bool stepped);
  void take_trace(std::vector<haptico::TraceSample>& buffer, std::ostream* trace, double t0);

  Scene scene_;
  haptico::DeviceCommand last_sent_{};
  bool have_last_sent_ = false;
  double haptic_hz_ = 1000.0;
  double collision_hz_ = 1000.0;
  std::unique_ptr<collette::CollisionWorld> world_;
  std::unique_ptr<haptico::HapticManager> manager_;
  std::unique_ptr<ForceController> force_controller_;
  std::unique_ptr<BridgingController> bridging_controller_;
  collette::ObjectId tool_id_ = -1;
  SessionReport report_;
};

/// The report as the JSON object `uh run --json` prints (nested: haptic.*, collision.*, force.*,
/// contact.*, energy.*), without the timeline.
std::string session_report_json(const SessionReport& report);

}  // namespace uh::controllers
