#include "uh/controllers/haptic_session.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

namespace uh::controllers {
namespace {

double median_of(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double steady_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

HapticSession::~HapticSession() {
  if (manager_) manager_->stop();
  if (world_) world_->stop();
}

Result<std::unique_ptr<HapticSession>> HapticSession::create(const Scene& scene, const SessionOptions& options,
                                                             const haptico::DeviceRegistry& registry) {
  std::unique_ptr<HapticSession> session(new HapticSession());
  session->scene_ = scene;
  session->haptic_hz_ = options.haptic_hz.value_or(scene.haptic_hz);
  session->collision_hz_ = options.collision_hz.value_or(scene.collision_hz);
  if (!(session->haptic_hz_ > 0.0) || session->haptic_hz_ > 10000.0)
    return Error{fmt::format("{}: haptic rate {} Hz is outside (0, 10000]", scene.source, session->haptic_hz_)};
  if (session->collision_hz_ < 0.0 || session->collision_hz_ > 10000.0)
    return Error{fmt::format("{}: collision rate {} Hz is outside [0, 10000]", scene.source, session->collision_hz_)};
  ForceControllerOptions force_options = scene.force;
  if (options.multi_rate) force_options.multi_rate = *options.multi_rate;
  force_options.coupling.period_s = 1.0 / session->haptic_hz_;
  const std::filesystem::path cache = options.cache_dir.empty() ? default_cache_dir() : options.cache_dir;

  session->world_ = std::make_unique<collette::CollisionWorld>(collette::CollisionWorldOptions{
      .rate_hz = session->collision_hz_,
      .raise_priority = options.raise_priority,
      .contact_margin = options.contact_margin.value_or(scene.contact_margin),
      .coherence_skin = options.coherence_skin.value_or(scene.coherence_skin)});
  auto& world = *session->world_;
  std::vector<collette::ObjectId> object_ids;
  for (const SceneObject& object : scene.objects) {
    auto tree = load_shape_tree(object.shape, cache, options.build_progress);
    if (!tree) return Error{fmt::format("{}: object '{}': {}", scene.source, object.name, tree.error().message)};
    auto id = world.add_object({.tree = *tree, .world_from_object = object.pose, .name = object.name});
    if (!id) return id.error();
    object_ids.push_back(*id);
  }
  auto tool_tree = load_shape_tree(scene.tool.shape, cache, options.build_progress);
  if (!tool_tree) return Error{fmt::format("{}: tool '{}': {}", scene.source, scene.tool.name, tool_tree.error().message)};
  // the tool's pose comes from the device on the first haptic tick (BridgingController)
  auto tool_id = world.add_object({.tree = *tool_tree, .has_initial_pose = false, .name = scene.tool.name});
  if (!tool_id) return tool_id.error();
  session->tool_id_ = *tool_id;

  // a simulated device advances its own time by one period per tick: it runs at the haptic rate
  // unless the scene says otherwise (else a 4 kHz session would play its script four times too fast)
  haptico::DeviceConfig device_config = scene.tool.device.config;
  if (scene.tool.device.driver.rfind("sim-", 0) == 0 && !device_config.has("rate_hz"))
    device_config.set("rate_hz", session->haptic_hz_);
  auto device = registry.create(scene.tool.device.driver, device_config);
  if (!device) return Error{fmt::format("{}: tool.device: {}", scene.source, device.error().message)};
  const std::size_t trace_capacity = static_cast<std::size_t>(std::max(1024.0, session->haptic_hz_ * 0.5));
  session->manager_ = std::make_unique<haptico::HapticManager>(
      std::move(device).value(),
      haptico::HapticManagerOptions{.rate_hz = session->haptic_hz_,
                                    .raise_priority = options.raise_priority,
                                    .trace_capacity = trace_capacity});
  if (auto opened = session->manager_->open(); !opened)
    return Error{fmt::format("{}: tool.device: {}", scene.source, opened.error().message)};

  const forcecomp::ForceComponent component({.params = scene.tool.force, .mode = scene.tool.mode,
                                             .side = forcecomp::ContactSide::kB});
  session->force_controller_ =
      std::make_unique<ForceController>(session->tool_id_, component, scene.tool.workspace, force_options);
  for (std::size_t i = 0; i < scene.objects.size(); ++i) {
    if (std::find(scene.watch.begin(), scene.watch.end(), scene.objects[i].name) == scene.watch.end()) continue;
    // the tool is B of every watched pair: the frames' forces push it out of the object
    if (auto w = world.add_collision_watcher(object_ids[i], session->tool_id_); !w) return w.error();
    session->force_controller_->add_watched(object_ids[i]);
  }
  session->bridging_controller_ = std::make_unique<BridgingController>(
      world, session->tool_id_, scene.tool.workspace, session->force_controller_.get());
  session->bridging_controller_->bind(*session->manager_);
  session->force_controller_->bind(world, *session->manager_);
  session->report_.scene = scene.name;
  return session;
}

void HapticSession::begin_run() {
  report_.timeline.clear();
  report_.collision_rates.clear();
  report_.force_max_step_n = 0.0;
  have_last_sent_ = false;
}

void HapticSession::take_trace(std::vector<haptico::TraceSample>& buffer, std::ostream* trace, double t0) {
  buffer.clear();
  manager_->drain_trace(buffer);
  for (const auto& s : buffer) {
    if (have_last_sent_)
      report_.force_max_step_n = std::max(report_.force_max_step_n, norm(s.sent.force - last_sent_.force));
    last_sent_ = s.sent;
    have_last_sent_ = true;
    report_.timeline.push_back({.time_s = s.tick_time_s - t0, .force_n = norm(s.sent.force), .torque_nm = norm(s.sent.torque)});
    if (trace != nullptr) haptico::write_trace_row(*trace, s);
  }
}

Status HapticSession::run(double seconds, const std::function<void(const LiveStatus&)>& on_status, std::ostream* trace) {
  if (!(seconds > 0.0)) return Error{"HapticSession::run: the duration must be positive"};
  begin_run();
  report_.timeline.reserve(static_cast<std::size_t>(seconds * haptic_hz_ * 1.05) + 16);
  if (trace != nullptr) haptico::write_trace_header(*trace);
  std::vector<haptico::TraceSample> buffer;
  buffer.reserve(static_cast<std::size_t>(haptic_hz_) + 16);

  if (auto started = world_->start(); !started) return started;
  const double t0 = steady_seconds();
  if (auto started = manager_->start(); !started) {
    world_->stop();
    return started;
  }
  const auto start = std::chrono::steady_clock::now();
  const auto end = start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(seconds));
  std::uint64_t last_steps = 0;
  double last_window_s = 0.0;
  auto next_status = start;
  while (std::chrono::steady_clock::now() < end) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    take_trace(buffer, trace, t0);
    const double now_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (now_s - last_window_s >= 0.1) {
      const std::uint64_t steps = world_->stats().steps;
      report_.collision_rates.push_back({.time_s = now_s, .rate_hz = static_cast<double>(steps - last_steps) / (now_s - last_window_s)});
      last_steps = steps;
      last_window_s = now_s;
    }
    if (on_status && std::chrono::steady_clock::now() >= next_status) {
      next_status += std::chrono::milliseconds(250);
      const auto fc = force_controller_->stats();
      on_status({.time_s = now_s,
                 .haptic_rate_hz = manager_->stats().loop.achieved_rate_hz,
                 .collision_rate_hz = report_.collision_rates.empty() ? 0.0 : report_.collision_rates.back().rate_hz,
                 .force_n = fc.last_force_n,
                 .pairs = fc.last_pairs});
    }
  }
  collect_report(seconds, false);  // before stop(): the loop statistics describe the run itself
  manager_->stop();
  world_->stop();
  take_trace(buffer, trace, t0);
  return Ok{};
}

Status HapticSession::run_stepped(double seconds, int ticks_per_collision_step, std::ostream* trace) {
  if (!(seconds > 0.0)) return Error{"HapticSession::run_stepped: the duration must be positive"};
  if (ticks_per_collision_step < 1) return Error{"HapticSession::run_stepped: ticks per collision step must be >= 1"};
  begin_run();
  if (trace != nullptr) haptico::write_trace_header(*trace);
  std::vector<haptico::TraceSample> buffer;
  const auto ticks = static_cast<std::int64_t>(std::llround(seconds * haptic_hz_));
  for (std::int64_t k = 0; k < ticks; ++k) {
    const double t = static_cast<double>(k) / haptic_hz_;
    // the collision step sees the tool pose of the previous tick, as the threaded world would
    if (k % ticks_per_collision_step == 0) world_->step(t);
    manager_->step(t);
    if (k % 256 == 255) take_trace(buffer, trace, 0.0);
  }
  take_trace(buffer, trace, 0.0);
  collision_hz_ = haptic_hz_ / ticks_per_collision_step;
  collect_report(seconds, true);
  return Ok{};
}

void HapticSession::collect_report(double seconds, bool stepped) {
  SessionReport& r = report_;
  r.stepped = stepped;
  r.seconds = seconds;
  const haptico::HapticStats hs = manager_->stats();
  r.haptic_target_hz = haptic_hz_;
  r.haptic_ticks = hs.ticks;
  if (stepped) {
    r.haptic_rate_hz = haptic_hz_;
  } else {
    r.haptic_rate_hz = hs.loop.achieved_rate_hz;
    r.haptic_missed_deadlines = hs.loop.missed_deadlines;
    r.jitter_p50_us = hs.loop.period_error.p50_ns * 1e-3;
    r.jitter_p99_us = hs.loop.period_error.p99_ns * 1e-3;
    r.jitter_p999_us = hs.loop.period_error.p999_ns * 1e-3;
    r.jitter_max_us = hs.loop.period_error.max_ns * 1e-3;
    r.tick_p99_us = hs.loop.callback_duration.p99_ns * 1e-3;
    r.tick_max_us = hs.loop.callback_duration.max_ns * 1e-3;
    r.haptic_priority_raised = hs.loop.priority_raised;
  }
  const collette::CollisionWorldStats ws = world_->stats();
  r.collision_target_hz = collision_hz_;
  r.collision_steps = ws.steps;
  r.query_median_us = ws.query_time.p50_ns * 1e-3;
  r.query_p99_us = ws.query_time.p99_ns * 1e-3;
  r.query_max_us = ws.query_time.max_ns * 1e-3;
  r.max_pairs = ws.max_pairs;
  r.truncated_frames = ws.truncated_frames;
  r.coherent_queries = ws.coherent_queries;
  if (stepped) {
    r.collision_rate_min_hz = r.collision_rate_median_hz = r.collision_rate_mean_hz = collision_hz_;
  } else {
    std::vector<double> rates;
    // the first window includes the threads' start-up
    for (std::size_t i = 1; i < r.collision_rates.size(); ++i) rates.push_back(r.collision_rates[i].rate_hz);
    if (rates.empty())
      for (const auto& s : r.collision_rates) rates.push_back(s.rate_hz);
    r.collision_rate_min_hz = rates.empty() ? 0.0 : *std::min_element(rates.begin(), rates.end());
    r.collision_rate_median_hz = median_of(rates);
    r.collision_rate_mean_hz = ws.rate_hz;
  }
  const ForceControllerStats fc = force_controller_->stats();
  r.force_max_n = fc.max_force_n;
  r.torque_max_nm = fc.max_torque_nm;
  r.force_max_raw_step_n = fc.max_force_step_n;
  r.force_nonfinite = fc.safety.nonfinite + hs.nonfinite;
  r.force_clamped = fc.safety.force_clamped + hs.force_clamped;
  r.torque_clamped = fc.safety.torque_clamped + hs.torque_clamped;
  r.stale_ticks = fc.safety.stale_ticks;
  r.contact_ticks = fc.contact_ticks;
  r.work_on_hand_j = fc.work_on_hand_j;
  r.multi_rate = force_controller_->options().multi_rate;
  r.coupling = force_controller_->options().use_coupling;
}

std::string session_report_json(const SessionReport& r) {
  nlohmann::json j = {
      {"scene", r.scene},
      {"mode", r.stepped ? "stepped" : "threaded"},
      {"seconds", r.seconds},
      {"haptic",
       {{"target_hz", r.haptic_target_hz},
        {"rate_hz", r.haptic_rate_hz},
        {"ticks", r.haptic_ticks},
        {"missed_deadlines", r.haptic_missed_deadlines},
        {"priority_raised", r.haptic_priority_raised},
        {"jitter_us", {{"p50", r.jitter_p50_us}, {"p99", r.jitter_p99_us}, {"p999", r.jitter_p999_us}, {"max", r.jitter_max_us}}},
        {"tick_us", {{"p99", r.tick_p99_us}, {"max", r.tick_max_us}}}}},
      {"collision",
       {{"target_hz", r.collision_target_hz},
        {"rate_hz", {{"min", r.collision_rate_min_hz}, {"median", r.collision_rate_median_hz}, {"mean", r.collision_rate_mean_hz}}},
        {"steps", r.collision_steps},
        {"query_us", {{"median", r.query_median_us}, {"p99", r.query_p99_us}, {"max", r.query_max_us}}},
        {"max_pairs", r.max_pairs},
        {"truncated_frames", r.truncated_frames},
        {"coherent_queries", r.coherent_queries}}},
      {"force",
       {{"max_n", r.force_max_n},
        {"max_torque_nm", r.torque_max_nm},
        {"max_step_n", r.force_max_step_n},
        {"max_raw_step_n", r.force_max_raw_step_n},
        {"nonfinite", r.force_nonfinite},
        {"clamped", r.force_clamped},
        {"torque_clamped", r.torque_clamped},
        {"stale_ticks", r.stale_ticks},
        {"multi_rate", r.multi_rate},
        {"coupling", r.coupling}}},
      {"contact", {{"ticks", r.contact_ticks}}},
      {"energy", {{"work_on_hand_j", r.work_on_hand_j}}}};
  return j.dump(2);
}

}  // namespace uh::controllers
