#include "uh/controllers/haptic_session.hpp"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <map>
#include <numbers>
#include <thread>
#include <tuple>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "uh/core/statistics.hpp"
#include "uh/devices/force_dimension_device.hpp"

namespace uh::controllers {
namespace {

double steady_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// The spring the proxy renders on a contact of `material` [N/m]: the gradient law's spring of a
// round tip, 2 pi r k (docs/scenes.md, `stiffness`), r the tool's largest inner sphere (the tip of a
// ball tool, the shaft of a stylus). 0 under the paper law, whose eps_c is no spring: the coupling's.
double proxy_spring_n_m(const forcecomp::ForceParams& force, const forcecomp::ContactMaterial& material,
                        const collette::SphereTree& tool_tree) {
  if (force.law != forcecomp::ForceLaw::kGradient) return 0.0;
  double radius = 0.0;
  for (const auto& leaf : tool_tree.leaves()) radius = std::max(radius, static_cast<double>(leaf.radius));
  return 2.0 * std::numbers::pi * radius * material.stiffness;
}

// Through the proxy a tool rests on an object's mesh, which lies up to the packing's surface gap G
// above its spheres, and a tool sphere gets its surface row from a pair within the margin (step_m).
// The world reports the object's pairs G - step_m / 2 farther, so that the row comes before the
// tool reaches the mesh when it moves up to half a step per step; the full G would cover a whole
// step, but the default session's queries took three times as long (docs/forcecomp.md).
double proxy_surface_margin(const SessionModel& model, std::size_t object) {
  const CompiledShape& o = model.objects[object];
  if (!model.scene.force.proxy.enabled || !o.surface || o.soft) return 0.0;
  return std::max(0.0, o.surface_gap_m - 0.5 * model.scene.force.proxy.step_m);
}

}  // namespace

Scene with_session_options(const Scene& scene, const SessionOptions& options) {
  Scene s = scene;
  s.haptic_hz = options.haptic_hz.value_or(scene.haptic_hz);
  s.collision_hz = options.collision_hz.value_or(scene.collision_hz);
  s.contact_margin = options.contact_margin.value_or(scene.contact_margin);
  s.coherence_skin = options.coherence_skin.value_or(scene.coherence_skin);
  if (options.multi_rate) s.force.multi_rate = *options.multi_rate;
  if (options.tick_force) s.force.tick_force = *options.tick_force;
  if (options.proxy)
    s.force.proxy.enabled = *options.proxy;
  else if (s.force.use_coupling)
    s.force.proxy.enabled = false;  // the proxy is the default, the coupling a choice: it wins
  if (s.force.proxy.enabled) s.force.use_coupling = false;  // the proxy is the simulated tool
  s.force.check_model = options.check_model;
  return s;
}

// One tool: its device's manager (its own haptic loop and limit chain), its controllers, what
// its haptic thread publishes and what the monitor accumulates of its run.
struct HapticSession::ToolRig {
  HapticSession* session = nullptr;
  std::int32_t index = 0;
  std::string path;  // the tool's place in the scene file, for messages: "tool" or "tools[i]"
  collette::ObjectId tool_id = -1;
  std::unique_ptr<haptico::HapticManager> manager;
  std::unique_ptr<ToolProxy> proxy;  // with ForceControllerOptions::proxy enabled
  std::unique_ptr<ForceController> force_controller;
  std::unique_ptr<BridgingController> bridging_controller;
  ScopedConnection sent_connection;

  // haptic thread -> readers of state()
  Delegator<const SessionState&> tick_event;
  LatestValue<SessionState> state_out;
  SessionState last_state{};  // guarded by the session's state_readers_
  std::uint64_t ticks_at_start = 0;
  std::atomic<double> haptic_rate_hz{0.0};  // monitor thread -> haptic thread

  // the monitor thread's (then the owner's) account of the run
  ToolReport report;
  haptico::DeviceCommand last_sent{};
  Vec3 last_sent_position{};  // the handle when last_sent was sent [m, device frame]
  double last_sent_time_s = 0.0;
  bool have_last_sent = false;

  // collision thread: per scene object, whether this tool touches it
  std::vector<std::uint8_t> touching;
  std::vector<std::uint8_t> touching_now;  // scratch of on_collision

  void on_tick_sent(const haptico::TraceSample& sample) {
    // haptic thread: one snapshot per tick through the triple buffer, no lock, no allocation
    SessionState& s = state_out.write_buffer();
    const WorkspaceMapping& mapping = bridging_controller->mapping();
    const Pose& handle = bridging_controller->last_pose();
    const Pose& tool = proxy ? force_controller->rendered_proxy() : handle;
    s.tool = index;
    s.time_s = sample.tick_time_s - session->t0_s_;
    s.tool_position_world = tool.position;
    s.tool_orientation_world = tool.rotation;
    s.handle_position_world = handle.position;
    s.force_world = mapping.to_world(sample.sent.force);
    s.torque_world = mapping.to_world(sample.sent.torque);
    s.contact_pairs = force_controller->last_pairs();
    s.haptic_ticks = manager->ticks() - ticks_at_start;
    s.missed_deadlines = manager->missed_deadlines();
    s.haptic_rate_hz = haptic_rate_hz.load(std::memory_order_relaxed);
    s.collision_rate_hz = session->collision_rate_hz_.load(std::memory_order_relaxed);
    s.buttons = sample.state.buttons;
    // what the tool felt goes back to the soft objects it presses (their own triple buffers)
    for (const auto& soft : session->soft_)
      if (soft) soft->post_tool_force(static_cast<std::size_t>(index), s.force_world);
    tick_event.broadcast(s);
    state_out.publish();
  }
};

HapticSession::HapticSession() = default;

HapticSession::~HapticSession() {
  const Status stopped = stop();
  (void)stopped;  // nobody is left to tell; the owner calls stop() to learn it
}

Result<std::unique_ptr<HapticSession>> HapticSession::create(const Scene& scene, const SessionOptions& options,
                                                             const haptico::DeviceRegistry& registry) {
  collette::IstCache cache(options.cache_dir);
  auto model = compile(with_session_options(scene, options), cache,
                       {.surface_beside_given_tree = false, .progress = options.build_progress});
  if (!model) return model.error();
  return create(std::move(model).value(), {.raise_priority = options.raise_priority}, registry);
}

Result<std::unique_ptr<HapticSession>> HapticSession::create(std::shared_ptr<const SessionModel> model,
                                                             const SessionRunOptions& options,
                                                             const haptico::DeviceRegistry& registry) {
  return create(std::move(model), std::vector<std::unique_ptr<haptico::HapticDevice>>{}, options, registry);
}

Result<std::unique_ptr<HapticSession>> HapticSession::create(
    std::shared_ptr<const SessionModel> model, std::vector<std::unique_ptr<haptico::HapticDevice>> devices,
    const SessionRunOptions& options, const haptico::DeviceRegistry& registry) {
  assert(model != nullptr && "uh::controllers::HapticSession::create(): no model");
  const std::size_t tools = model->scene.tools.size();
  if (devices.size() > tools)
    return Error{fmt::format("{}: {} devices given for {} tool(s)", model->scene.source, devices.size(), tools),
                 ErrorKind::kInvalid};
  devices.resize(tools);  // the rest open through the registry
  std::unique_ptr<HapticSession> session(new HapticSession());
  session->model_ = std::move(model);
  session->haptic_hz_ = session->model_->scene.haptic_hz;
  session->collision_hz_ = session->model_->scene.collision_hz;
  if (Status s = session->add_objects(options); !s) return s.error();
  for (std::size_t t = 0; t < tools; ++t)
    if (Status s = session->add_tool(t, std::move(devices[t]), options, registry); !s) return s.error();
  HapticSession& self = *session;
  self.collision_connection_ = self.world_->on_collision().connect<&HapticSession::on_collision>(self);
  self.step_connection_ = self.world_->on_step().connect<&HapticSession::on_step>(self);  // after the proxies'
  self.report_.scene = self.model_->scene.name;
  return session;
}

Status HapticSession::add_objects(const SessionRunOptions& options) {
  const Scene& scene = model_->scene;
  world_ = std::make_unique<collette::CollisionWorld>(collette::CollisionWorldOptions{
      .rate_hz = collision_hz_,
      .raise_priority = options.raise_priority,
      // the proxy's constraints are the pairs within the margin: it may step no farther than that
      // (its mesh rows come with the pairs: docs/forcecomp.md, "Resting on the mesh")
      .contact_margin = std::max(scene.contact_margin, scene.force.proxy.enabled ? scene.force.proxy.step_m : 0.0),
      .coherence_skin = scene.coherence_skin});
  for (std::size_t i = 0; i < scene.objects.size(); ++i) {
    const SceneObject& object = scene.objects[i];
    auto& soft = soft_.emplace_back();
    if (model_->objects[i].soft) {
      auto made = SoftSimulation::create(model_->objects[i].soft, model_->objects[i].tree, object.pose,
                                         scene.tools.size());
      if (!made) return Error{fmt::format("{}: object '{}': {}", scene.source, object.name, made.error().message)};
      soft = std::move(*made);
    }
    auto id = world_->add_object({.tree = model_->objects[i].tree,
                                  .world_from_object = object.pose,
                                  .coverage = model_->objects[i].coverage,
                                  .name = object.name,
                                  .deformed_trees = soft ? &soft->trees() : nullptr,
                                  .extra_margin_m = proxy_surface_margin(*model_, i)});
    if (!id) return id.error();
    object_ids_.push_back(*id);
  }
  return Ok{};
}

Status HapticSession::add_tool(std::size_t t, std::unique_ptr<haptico::HapticDevice> device,
                               const SessionRunOptions& options, const haptico::DeviceRegistry& registry) {
  const Scene& scene = model_->scene;
  const SceneTool& tool = scene.tools[t];
  auto rig = std::make_unique<ToolRig>();
  rig->session = this;
  rig->index = static_cast<std::int32_t>(t);
  rig->path = uh::scene::tool_path(scene, t);
  // the tool's pose comes from its device on its first haptic tick (BridgingController)
  auto tool_id = world_->add_object({.tree = model_->tools[t].tree,
                                     .has_initial_pose = false,
                                     .coverage = model_->tools[t].coverage,
                                     .name = tool.name});
  if (!tool_id) return tool_id.error();
  rig->tool_id = *tool_id;
  if (Status s = open_device(*rig, std::move(device), options, registry); !s) return s;
  if (Status s = wire_controllers(*rig); !s) return s;
  ToolRig& r = *rig;
  r.sent_connection = r.manager->sent_on_haptic_tick().connect<&ToolRig::on_tick_sent>(r);
  r.touching.assign(scene.objects.size(), 0);
  r.touching_now.assign(scene.objects.size(), 0);
  r.report.tool = tool.name;
  rigs_.push_back(std::move(rig));
  return Ok{};
}

// The tool's device through the registry, as its scene entry names it
Result<std::unique_ptr<haptico::HapticDevice>> HapticSession::make_device(const ToolRig& rig,
                                                                         const haptico::DeviceRegistry& registry) const {
  const Scene& scene = model_->scene;
  const SceneTool& tool = scene.tools[static_cast<std::size_t>(rig.index)];
  // a simulated device advances its own time by one period per tick: it runs at the haptic rate
  // unless the scene says otherwise (else a 4 kHz session would play its script four times too fast)
  haptico::DeviceConfig device_config = tool.device.config;
  if (tool.device.driver.rfind("sim-", 0) == 0 && !device_config.has("rate_hz"))
    device_config.set("rate_hz", haptic_hz_);
  auto device = registry.create(tool.device.driver, device_config);
  if (!device)
    return Error{fmt::format("{}: {}.device: {}", scene.source, rig.path, device.error().message),
                 device.error().kind};
  return device;
}

Status HapticSession::open_device(ToolRig& rig, std::unique_ptr<haptico::HapticDevice> given,
                                  const SessionRunOptions& options, const haptico::DeviceRegistry& registry) {
  const Scene& scene = model_->scene;
  const SceneTool& tool = scene.tools[static_cast<std::size_t>(rig.index)];
  if (!given) {
    auto made = make_device(rig, registry);
    if (!made) return made.error();
    given = std::move(made).value();
  }
  const std::size_t trace_capacity = static_cast<std::size_t>(std::max(1024.0, haptic_hz_ * 0.5));
  rig.manager = std::make_unique<haptico::HapticManager>(
      std::move(given),
      haptico::HapticManagerOptions{.rate_hz = haptic_hz_,
                                    .raise_priority = options.raise_priority,
                                    .trace_capacity = trace_capacity,
                                    .limits = {.tool = {.max_force_n = tool.force.max_force_n,
                                                        .max_torque_nm = tool.force.max_torque_nm},
                                               .safety = scene.safety_limits,
                                               .rate = scene.rate_limit},
                                    .fault_group = &fault_group_});
  if (auto opened = rig.manager->open(); !opened)
    return Error{fmt::format("{}: {}.device: {}", scene.source, rig.path, opened.error().message),
                 opened.error().kind};
  return Ok{};
}

Status HapticSession::wire_controllers(ToolRig& rig) {
  const Scene& scene = model_->scene;
  const std::size_t t = static_cast<std::size_t>(rig.index);
  const SceneTool& tool = scene.tools[t];
  const ForceControllerOptions& force_options = scene.force;
  const forcecomp::ForceComponent component(
      {.params = tool.force, .mode = tool.mode, .side = forcecomp::ContactSide::kB});
  rig.force_controller = std::make_unique<ForceController>(rig.tool_id, component, tool.workspace, force_options);
  if (force_options.proxy.enabled) {
    rig.proxy = std::make_unique<ToolProxy>(*world_, rig.tool_id, *model_->tools[t].tree, force_options.proxy,
                                            tool.mode == forcecomp::ForceMode::k6Dof);
    rig.force_controller->render_through(rig.proxy.get());
  }
  // the tool is B of every watcher: the frames' forces push it out of the objects. Watching every
  // object is one watcher of the tool against everything (the broad phase picks the objects it
  // touches); a coherence skin keeps one watcher per pair (the kept candidates belong to a pair).
  // A tool against everything also meets the other tools: the force controller renders only its
  // watched objects, so tools pass through each other.
  const bool watch_all = scene.watch.size() == scene.objects.size() && !scene.objects.empty() &&
                         !(scene.coherence_skin > 0.0);
  if (watch_all) {
    auto w = world_->add_tool_watcher(rig.tool_id);
    if (!w) return w.error();
    rig.force_controller->read_frames_of(*w);
  }
  for (std::size_t i = 0; i < scene.objects.size(); ++i) {
    if (std::find(scene.watch.begin(), scene.watch.end(), scene.objects[i].name) == scene.watch.end()) continue;
    if (!watch_all) {
      auto w = world_->add_collision_watcher(object_ids_[i], rig.tool_id);
      if (!w) return w.error();
      rig.force_controller->read_frames_of(*w);
    }
    const forcecomp::ContactMaterial& material = model_->materials[t][i];
    rig.force_controller->add_watched(object_ids_[i], model_->objects[i].coverage * model_->tools[t].coverage,
                                      &material);
    if (rig.proxy)
      rig.proxy->watch(object_ids_[i], {.friction_static = material.friction_static,
                                        .friction_dynamic = material.friction_dynamic,
                                        .stiffness_n_m = proxy_spring_n_m(tool.force, material, *model_->tools[t].tree),
                                        .object_texture = material.object_texture,
                                        .tool_texture = material.tool_texture,
                                        // a soft object's rest surface is not where it is: its spheres are
                                        .surface = soft_[i] ? nullptr : model_->objects[i].surface});
    // the proxy rests on a soft object's spheres within the margin: its loads go by nearness; the
    // spring to it, or the penalty's local model, is felt in series with the object's compliance
    if (soft_[i]) {
      if (rig.proxy)
        soft_[i]->rest_on_proxy(t, std::max(force_options.proxy.smoothing_m, force_options.proxy.penetration_m));
      rig.force_controller->feel_compliance_of(&soft_[i]->compliance(t));
    }
  }
  if (rig.proxy) rig.proxy->bind();
  rig.bridging_controller = std::make_unique<BridgingController>(*world_, rig.tool_id, tool.workspace,
                                                                 rig.force_controller.get(), rig.proxy.get());
  rig.bridging_controller->bind(*rig.manager);
  rig.force_controller->bind(*world_, *rig.manager);
  return Ok{};
}

DelegateSink<const SessionState&> HapticSession::on_haptic_tick(std::size_t tool) {
  assert(tool < rigs_.size() && "uh::controllers::HapticSession::on_haptic_tick(): no such tool");
  return DelegateSink{rigs_[tool]->tick_event};
}

DelegateSink<const haptico::DeviceState&, haptico::DeviceCommand&> HapticSession::force_on_haptic_tick(
    std::size_t tool) {
  assert(tool < rigs_.size() && "uh::controllers::HapticSession::force_on_haptic_tick(): no such tool");
  return rigs_[tool]->manager->force_on_haptic_tick();
}

void HapticSession::halt() {
  for (auto& rig : rigs_) rig->manager->halt();
}

void HapticSession::resume() {
  for (auto& rig : rigs_) rig->manager->resume();
}

Status HapticSession::begin_run() {
  if (phase_ != Phase::kReady)
    return Error{"HapticSession: a session runs once; create a new one to run again"};
  report_.collision_rates.clear();
  for (auto& rig : rigs_) {
    rig->report.timeline.clear();
    rig->report.force_max_step_n = 0.0;
    rig->report.force_max_n = 0.0;
    rig->report.torque_max_nm = 0.0;
    rig->report.work_on_hand_j = 0.0;
    rig->report.contact_squared_speed_integral = 0.0;
    rig->have_last_sent = false;
    rig->ticks_at_start = rig->manager->ticks();
  }
  return Ok{};
}

void HapticSession::on_collision(collette::ObjectId a, collette::ObjectId b, const ContactFrame& frame) {
  // collision thread: edges of the overlap become events for the owner. The session registered
  // its objects first, so an object's world id is its index in the scene.
  ToolRig* rig = nullptr;
  for (auto& r : rigs_)
    if (r->tool_id == b) rig = r.get();
  if (rig == nullptr) return;
  for (std::size_t i = 0; i < soft_.size(); ++i)
    if (soft_[i]) soft_[i]->post_contacts(static_cast<std::size_t>(rig->index), object_ids_[i], frame);
  if (rig->proxy) return;  // a proxy's contacts are its constraints' (on_step)
  auto& touching = rig->touching;
  if (a != ContactFrame::kEveryObject) {
    if (a < 0 || static_cast<std::size_t>(a) >= touching.size()) return;
    const bool now = frame.total_volume > 0.0;
    contact_edge(*rig, a, now, frame.time_s, now ? frame.total_volume : 0.0, now ? frame.pair_count : 0);
    return;
  }
  // the tool against everything: a section per object it touches; the others are apart (a
  // section of another tool is no scene object: not an event)
  auto& now = rig->touching_now;
  std::fill(now.begin(), now.end(), std::uint8_t{0});
  for (const ContactSection& s : frame.sections()) {
    if (s.object_a < 0 || static_cast<std::size_t>(s.object_a) >= touching.size() || !(s.total_volume > 0.0))
      continue;
    now[static_cast<std::size_t>(s.object_a)] = 1;
    contact_edge(*rig, s.object_a, true, frame.time_s, s.total_volume, s.pair_count);
  }
  for (std::size_t i = 0; i < touching.size(); ++i)
    if (now[i] == 0) contact_edge(*rig, static_cast<collette::ObjectId>(i), false, frame.time_s, 0.0, 0);
}

void HapticSession::on_step(double time_s) {
  // collision thread, after every proxy's own step: through a proxy the tool rests on the surface
  // (on the mesh, above the spheres), so its contact is its constraint rows in contact, not overlap;
  // a soft object takes the force where the proxy now rests, not where the step's query had it
  for (auto& rig : rigs_) {
    if (!rig->proxy) {  // a penalty tool's model is built from the tree this step took: its compliance
      for (const auto& soft : soft_)
        if (soft) soft->hand_over_compliance(static_cast<std::size_t>(rig->index));
      continue;
    }
    const ToolProxy& proxy = *rig->proxy;
    for (const auto& soft : soft_)
      if (soft) soft->rest_proxy_at(static_cast<std::size_t>(rig->index), proxy.pose());
    for (std::size_t k = 0; k < proxy.watched_count(); ++k) {
      const std::int32_t rows = proxy.contact_rows(k);
      contact_edge(*rig, proxy.watched_object(k), rows > 0, time_s, 0.0, rows);
    }
  }
}

void HapticSession::contact_edge(ToolRig& rig, collette::ObjectId object, bool touching, double time_s,
                                 double volume, std::int32_t pairs) {
  std::uint8_t& was = rig.touching[static_cast<std::size_t>(object)];
  if (touching == (was != 0)) return;
  was = touching ? 1 : 0;
  const ContactEvent event{.kind = touching ? ContactEventKind::kBegin : ContactEventKind::kEnd,
                           .object = object,
                           .tool = rig.index,
                           .time_s = time_s - t0_s_,
                           .volume = volume,
                           .pairs = pairs};
  if (!events_.try_push(event)) dropped_events_.increment();
}

SessionState HapticSession::state(std::size_t tool) {
  assert(tool < rigs_.size() && "uh::controllers::HapticSession::state(): no such tool");
  const std::lock_guard lock(state_readers_);
  ToolRig& rig = *rigs_[tool];
  if (rig.state_out.update()) rig.last_state = rig.state_out.read_buffer();
  rig.last_state.tool = rig.index;  // also before the first tick
  return rig.last_state;
}

Status HapticSession::set_object_pose(std::int32_t object, const Pose& world_from_object) {
  if (object < 0 || static_cast<std::size_t>(object) >= object_ids_.size())
    return Error{
        fmt::format("{}: there is no object {} (the scene has {})", model_->scene.name, object, object_ids_.size())};
  world_->set_pose(object_ids_[static_cast<std::size_t>(object)], world_from_object);
  if (const auto& soft = soft_[static_cast<std::size_t>(object)]) soft->set_pose(world_from_object);
  return Ok{};
}

bool HapticSession::poll_event(ContactEvent& out) { return events_.try_pop(out); }

void HapticSession::take_trace(ToolRig& rig, std::vector<haptico::TraceSample>& buffer, std::ostream* trace) {
  buffer.clear();
  rig.manager->drain_trace(buffer);
  const double halted_at_s = halted_at_s_.load(std::memory_order_relaxed);
  ToolReport& report = rig.report;
  for (const auto& s : buffer) {
    if (trace != nullptr) haptico::write_trace_row(*trace, s);
    // the ticks after stop() asked for zero force, and the zero sent as the haptic loop ended,
    // are in the trace, not in the report: the report describes the run, not its end
    if (s.tick_time_s >= halted_at_s || (s.flags & haptico::kTraceStopped) != 0) continue;
    if (rig.have_last_sent) {
      report.force_max_step_n = std::max(report.force_max_step_n, norm(s.sent.force - rig.last_sent.force));
      // energy the device put into the hand over the last period: the force it held then (as
      // sent, after every limit) times the handle's displacement since. Exact for a zero-order
      // hold; F . v dt at the sample instant would miss the sampled-data energy gain that makes a
      // too stiff coupling active
      const double work = dot(rig.last_sent.force, s.state.position - rig.last_sent_position);
      if (std::isfinite(work)) report.work_on_hand_j += work;
      const double period = s.state.time_s - rig.last_sent_time_s;
      const double squared = squared_norm(s.state.position - rig.last_sent_position) / period;
      if (period > 0.0 && std::isfinite(squared) && squared_norm(rig.last_sent.force) > 0.0) report.contact_squared_speed_integral += squared;
    }
    rig.last_sent = s.sent;
    rig.last_sent_position = s.state.position;
    rig.last_sent_time_s = s.state.time_s;
    rig.have_last_sent = true;
    report.force_max_n = std::max(report.force_max_n, norm(s.sent.force));
    report.torque_max_nm = std::max(report.torque_max_nm, norm(s.sent.torque));
    report.timeline.push_back(
        {.time_s = s.tick_time_s - t0_s_, .force_n = norm(s.sent.force), .torque_nm = norm(s.sent.torque)});
  }
}

void HapticSession::monitor() {
  std::vector<haptico::TraceSample> buffer;
  buffer.reserve(static_cast<std::size_t>(haptic_hz_) + 16);
  const double start_s = started_s_;
  std::uint64_t last_steps = 0;
  std::vector<std::uint64_t> last_ticks;
  for (const auto& rig : rigs_) last_ticks.push_back(rig->manager->ticks());
  double last_window_s = 0.0;
  // a last pass after stop() woke it, as after every 20 ms
  for (bool stopping = false; !stopping;) {
    {
      std::unique_lock lock(monitor_mutex_);
      stopping = monitor_wake_.wait_for(lock, std::chrono::milliseconds(20), [this] { return monitor_stop_; });
    }
    // the CSV trace is the first tool's (its columns describe one device)
    for (std::size_t t = 0; t < rigs_.size(); ++t) take_trace(*rigs_[t], buffer, t == 0 ? trace_ : nullptr);
    const double now_s = steady_seconds() - start_s;
    if (now_s - last_window_s >= 0.1) {
      const std::uint64_t steps = world_->stats().steps;
      const double window = now_s - last_window_s;
      const double collision_rate = static_cast<double>(steps - last_steps) / window;
      report_.collision_rates.push_back({.time_s = now_s, .rate_hz = collision_rate});
      collision_rate_hz_.store(collision_rate, std::memory_order_relaxed);
      for (std::size_t t = 0; t < rigs_.size(); ++t) {
        const std::uint64_t ticks = rigs_[t]->manager->ticks();
        rigs_[t]->haptic_rate_hz.store(static_cast<double>(ticks - last_ticks[t]) / window,
                                       std::memory_order_relaxed);
        last_ticks[t] = ticks;
      }
      last_steps = steps;
      last_window_s = now_s;
    }
  }
}

Status HapticSession::start(std::ostream* trace) {
  if (auto ready = begin_run(); !ready) return ready;
  for (auto& rig : rigs_) rig->report.timeline.reserve(static_cast<std::size_t>(10.0 * haptic_hz_) + 16);
  trace_ = trace;
  if (trace != nullptr) haptico::write_trace_header(*trace);
  started_s_ = steady_seconds();
  t0_s_ = started_s_;
  if (auto started = world_->start(); !started) return started;
  for (std::size_t i = 0; i < soft_.size(); ++i) {
    if (!soft_[i]) continue;
    // a failed step leaves the object frozen under the tool: every device gets zero at its next tick
    if (auto started = soft_[i]->start(soft_rate_hz(i), [this] { fault_group_.trip(); }); !started) {
      stop_soft();
      world_->stop();
      return started;
    }
  }
  for (std::size_t t = 0; t < rigs_.size(); ++t) {
    if (auto started = rigs_[t]->manager->start(); !started) {
      // the loops already running end with zero
      for (std::size_t u = 0; u < t; ++u) rigs_[u]->manager->stop();
      stop_soft();
      world_->stop();
      if (rigs_.size() == 1) return started;
      return Error{fmt::format("{}: {}.device: {}", model_->scene.source, rigs_[t]->path, started.error().message),
                   started.error().kind};
    }
  }
  phase_ = Phase::kRunning;
  monitor_stop_ = false;
  monitor_thread_ = std::thread([this] { monitor(); });
  return Ok{};
}

bool HapticSession::any_fault() const {
  return std::any_of(rigs_.begin(), rigs_.end(), [](const auto& rig) { return rig->manager->faulted(); });
}

bool HapticSession::ended_by_itself() const {
  return phase_ == Phase::kRunning && (!haptic_threads_running() || !world_->running() || !soft_threads_running() ||
                                       any_fault() || fault_group_.tripped());
}

bool HapticSession::soft_threads_running() const {
  return std::all_of(soft_.begin(), soft_.end(), [](const auto& soft) { return !soft || soft->running(); });
}

bool HapticSession::haptic_threads_running() const {
  return std::all_of(rigs_.begin(), rigs_.end(), [](const auto& rig) { return rig->manager->running(); });
}

std::string HapticSession::tool_label(std::int32_t tool) const {
  // one-tool sessions say nothing more (their messages are as they always were)
  if (rigs_.size() == 1) return {};
  return fmt::format("{} '{}': ", rigs_[static_cast<std::size_t>(tool)]->path,
                     model_->scene.tools[static_cast<std::size_t>(tool)].name);
}

Status HapticSession::thread_error() const {
  // the first haptic thread that ended by a throw (the others were zeroed with it)
  for (const auto& rig : rigs_)
    if (Status s = rig->manager->thread_status(); !s)
      return Error{fmt::format("{}: {}{}", model_->scene.source, tool_label(rig->index), s.error().message),
                   s.error().kind};
  return Ok{};
}

Status HapticSession::device_error() const {
  // the first device that faulted (the others were zeroed with it); in several-tool scenes the
  // message names the tool too
  for (const auto& rig : rigs_) {
    if (Status device = rig->manager->device_status(); !device)
      return Error{fmt::format("{}: {}{}{}", model_->scene.source, tool_label(rig->index), device.error().message,
                               rigs_.size() > 1 ? "; every device was sent zero force" : ""),
                   device.error().kind};
  }
  return Ok{};
}

Status HapticSession::stop() {
  if (phase_ != Phase::kRunning) return stopped_;
  // zero force from the next tick on, before anything that takes time
  const double halted_at_s = steady_seconds();
  halted_at_s_.store(halted_at_s, std::memory_order_relaxed);
  for (auto& rig : rigs_) rig->manager->halt();
  const bool haptic_alive = haptic_threads_running();
  const bool collision_alive = world_->running();
  const double seconds = halted_at_s - started_s_;
  {
    std::lock_guard lock(monitor_mutex_);
    monitor_stop_ = true;
  }
  monitor_wake_.notify_all();
  monitor_thread_.join();
  collect_report(seconds, false);  // before the loops stop: their statistics describe the run itself
  for (auto& rig : rigs_) rig->manager->stop();
  stop_soft();
  collect_soft_report();
  world_->stop();
  record_proxy_ends();
  // the haptic threads are joined and the devices got zero: this thread becomes the states' writer
  for (std::size_t t = 0; t < rigs_.size(); ++t) {
    SessionState last = state(t);
    last.force_world = {};
    last.torque_world = {};
    rigs_[t]->state_out.write(last);
  }
  std::vector<haptico::TraceSample> buffer;
  for (std::size_t t = 0; t < rigs_.size(); ++t) take_trace(*rigs_[t], buffer, t == 0 ? trace_ : nullptr);
  publish_report();
  phase_ = Phase::kStopped;
  if (Status haptic = thread_error(); !haptic)
    stopped_ = haptic;
  else if (Status device = device_error(); !device)
    stopped_ = device;
  else if (!haptic_alive)
    stopped_ = Error{"the haptic thread ended before the session was stopped", ErrorKind::kThread};
  else if (!collision_alive)
    stopped_ = Error{"the collision thread ended before the session was stopped", ErrorKind::kThread};
  else if (trace_ != nullptr && !*trace_)
    stopped_ = Error{"the trace could not be written", ErrorKind::kFile};
  else if (Status soft = soft_error(); !soft)
    stopped_ = soft;
  return stopped_;
}

Result<const soft::SurfaceMesh*> HapticSession::soft_surface(std::size_t object) const {
  if (object >= soft_.size())
    return Error{fmt::format("no scene object {} (the scene has {})", object, soft_.size()), ErrorKind::kInvalid};
  if (!soft_[object])
    return Error{fmt::format("object '{}' is rigid: it has no deformed vertices", scene().objects[object].name),
                 ErrorKind::kInvalid};
  return &soft_[object]->body().surface;
}

Result<std::size_t> HapticSession::soft_vertex_count(std::size_t object) const {
  auto surface = soft_surface(object);
  if (!surface) return surface.error();
  return (*surface)->vertices.size();
}

Result<std::uint64_t> HapticSession::soft_vertices(std::size_t object, std::span<float> xyz) {
  auto count = soft_vertex_count(object);
  if (!count) return count.error();
  if (xyz.size() < 3 * *count)
    return Error{fmt::format("object '{}' has {} deformed vertices: the buffer of {} floats holds fewer than {}",
                             scene().objects[object].name, *count, xyz.size(), 3 * *count),
                 ErrorKind::kInvalid};
  return soft_[object]->read_surface(xyz);
}

double HapticSession::soft_rate_hz(std::size_t object) const {
  return scene().objects[object].deformable.value().rate_hz;  // soft_[object] exists: it is deformable
}

void HapticSession::stop_soft() {
  for (auto& soft : soft_)
    if (soft) soft->stop();
}

void HapticSession::collect_soft_report() {
  report_.soft.clear();
  for (std::size_t i = 0; i < soft_.size(); ++i)
    if (soft_[i]) report_.soft.push_back(soft_object_report(i));
}

SessionReport::SoftObjectReport HapticSession::soft_object_report(std::size_t object) const {
  const SoftSimulation& soft = *soft_[object];
  const FixedRateLoopStats loop = soft.stats();
  SessionReport::SoftObjectReport r{.object = scene().objects[object].name,
                                    .tetrahedra = static_cast<std::int64_t>(soft.body().mesh.tets.size()),
                                    .target_hz = soft_rate_hz(object),
                                    .steps = soft.steps(),
                                    .samples = soft.record()};
  // a stepped run's steps are simulated time: no wall-clock rate or duration to report
  if (loop.ticks == 0) return r;
  r.rate_hz = loop.achieved_rate_hz;
  r.missed_deadlines = loop.missed_deadlines;
  r.step_p50_ms = loop.callback_duration.p50_ns * 1e-6;
  r.step_p99_ms = loop.callback_duration.p99_ns * 1e-6;
  r.step_max_ms = loop.callback_duration.max_ns * 1e-6;
  return r;
}

Status HapticSession::soft_error() const {
  for (std::size_t i = 0; i < soft_.size(); ++i)
    if (soft_[i] && !soft_[i]->failure())
      return Error{fmt::format("object '{}': the simulation stopped: {}", model_->scene.objects[i].name,
                               soft_[i]->failure().error().message),
                   ErrorKind::kThread};
  return Ok{};
}

Status HapticSession::run(double seconds, const std::function<void(const SessionState&)>& on_status,
                          std::ostream* trace) {
  if (!(seconds > 0.0)) return Error{fmt::format("the run's duration must be positive (got {} s)", seconds)};
  if (auto started = start(trace); !started) return started;
  // an exception from on_status must not leave the threads running: stop() (idempotent) either way
  struct StopOnExit {
    HapticSession& session;
    ~StopOnExit() { (void)session.stop(); }
  } stop_on_exit{*this};
  const auto begin = std::chrono::steady_clock::now();
  const auto end = begin + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                               std::chrono::duration<double>(seconds));
  auto next_status = begin + std::chrono::milliseconds(250);
  // a stop request is seen within 20 ms; a thread that ended by itself (the haptic one has sent
  // zero already; a soft object's simulation leaves its object frozen), or a device fault (every
  // device gets zero from its next tick on), ends the run
  while (std::chrono::steady_clock::now() < end && !stop_requested_.load(std::memory_order_relaxed) &&
         !ended_by_itself()) {
    const auto soon = std::chrono::steady_clock::now() + std::chrono::milliseconds(20);
    std::this_thread::sleep_until(std::min({end, next_status, soon}));
    if (on_status && std::chrono::steady_clock::now() >= next_status) {
      next_status += std::chrono::milliseconds(250);
      on_status(state());
    }
  }
  // a stop request or a device fault ended it before its time
  const bool early = std::chrono::steady_clock::now() < end &&
                     (stop_requested_.load(std::memory_order_relaxed) || any_fault());
  Status stopped = stop();
  report_.stopped_early = early;
  return stopped;
}

Status HapticSession::run_stepped(double seconds, int ticks_per_collision_step, std::ostream* trace) {
  if (!(seconds > 0.0))
    return Error{fmt::format("the stepped run's duration must be positive (got {} s)", seconds)};
  if (ticks_per_collision_step < 1)
    return Error{
        fmt::format("ticks per collision step must be at least 1 (got {})", ticks_per_collision_step)};
  if (auto ready = begin_run(); !ready) return ready;
  t0_s_ = 0.0;
  for (auto& rig : rigs_) rig->haptic_rate_hz.store(haptic_hz_, std::memory_order_relaxed);
  collision_rate_hz_.store(haptic_hz_ / ticks_per_collision_step, std::memory_order_relaxed);
  if (trace != nullptr) haptico::write_trace_header(*trace);
  std::vector<haptico::TraceSample> buffer;
  const auto drain = [&] {
    for (std::size_t t = 0; t < rigs_.size(); ++t) take_trace(*rigs_[t], buffer, t == 0 ? trace : nullptr);
  };
  const auto ticks = static_cast<std::int64_t>(std::llround(seconds * haptic_hz_));
  // the soft objects step in simulated time too, each at its own rate (in whole ticks)
  std::vector<std::int64_t> ticks_per_soft_step(soft_.size(), 1);
  for (std::size_t i = 0; i < soft_.size(); ++i)
    if (soft_[i]) ticks_per_soft_step[i] = std::max<std::int64_t>(1, std::llround(haptic_hz_ / soft_rate_hz(i)));
  Status soft_stepped = Ok{};
  std::int64_t k = 0;
  for (; k < ticks && !stop_requested_.load(std::memory_order_relaxed) && !any_fault() && soft_stepped; ++k) {
    const double t = static_cast<double>(k) / haptic_hz_;
    for (std::size_t i = 0; i < soft_.size() && soft_stepped; ++i)
      if (soft_[i] && k % ticks_per_soft_step[i] == 0)
        soft_stepped = soft_[i]->step(static_cast<double>(ticks_per_soft_step[i]) / haptic_hz_);
    // the collision step sees the tool poses of the previous tick, as the threaded world would
    if (k % ticks_per_collision_step == 0) world_->step(t);
    for (auto& rig : rigs_) rig->manager->step(t);
    if (k % 256 == 255) drain();
  }
  // a stepped run ends like a threaded one: zero to every device, traced
  for (auto& rig : rigs_) rig->manager->stop();
  drain();
  collision_hz_ = haptic_hz_ / ticks_per_collision_step;
  collect_report(static_cast<double>(k) / haptic_hz_, true);
  collect_soft_report();
  record_proxy_ends();
  publish_report();
  report_.stopped_early = k < ticks;
  phase_ = Phase::kStopped;
  if (!soft_stepped) return soft_stepped;
  return device_error();
}

// One tool's part of the report: its device, its haptic loop, its force controller and proxy
void HapticSession::collect_tool_report(ToolRig& rig, bool stepped) {
  ToolReport& t = rig.report;
  const haptico::HapticStats hs = rig.manager->stats();
  t.haptic_target_hz = haptic_hz_;
  t.haptic_ticks = hs.ticks;
  const haptico::DeviceInfo& info = rig.manager->device_info();
  t.device = {.driver = model_->scene.tools[static_cast<std::size_t>(rig.index)].device.driver,
              .name = info.name,
              .model = info.model,
              .serial = info.serial,
              .max_force_n = info.max_force_n};
  if (const auto* fd = dynamic_cast<const devices::ForceDimensionDevice*>(&rig.manager->device()))
    t.device.com_rate_hz = fd->com_rate_hz();
  if (stepped) {
    t.haptic_rate_hz = haptic_hz_;
  } else {
    t.haptic_rate_hz = hs.loop.achieved_rate_hz;
    t.haptic_missed_deadlines = hs.loop.missed_deadlines;
    t.jitter_p50_us = hs.loop.period_error.p50_ns * 1e-3;
    t.jitter_p99_us = hs.loop.period_error.p99_ns * 1e-3;
    t.jitter_p999_us = hs.loop.period_error.p999_ns * 1e-3;
    t.jitter_max_us = hs.loop.period_error.max_ns * 1e-3;
    t.tick_p50_us = hs.loop.callback_duration.p50_ns * 1e-3;
    t.tick_p99_us = hs.loop.callback_duration.p99_ns * 1e-3;
    t.tick_max_us = hs.loop.callback_duration.max_ns * 1e-3;
    t.haptic_priority_raised = hs.loop.priority_raised;
  }
  const ForceController& fcon = *rig.force_controller;
  const ForceControllerStats fc = fcon.stats();
  t.force_max_raw_step_n = fc.max_force_step_n;
  t.force_nonfinite = fc.safety.nonfinite + hs.nonfinite;
  t.force_clamped = hs.force_clamped;
  t.torque_clamped = hs.torque_clamped;
  t.limits = hs.limits;
  t.zeroed_ticks = hs.zeroed_ticks;
  t.stale_ticks = fc.safety.stale_ticks;
  t.contact_ticks = fc.contact_ticks;
  t.multi_rate = fcon.options().multi_rate;
  t.tick_force = fcon.options().tick_force == TickForce::kModel ? "model" : "exact";
  t.model_clamped_ticks = fc.model_clamped_ticks;
  t.model_held_ticks = fc.model_held_ticks;
  t.model_checked_ticks = fc.model_checked_ticks;
  t.model_error_rms_n = fc.model_error_rms_n;
  t.model_error_max_n = fc.model_error_max_n;
  t.coupling = fcon.options().use_coupling;
  t.proxy = rig.proxy != nullptr;
  if (rig.proxy) t.proxy_stats = rig.proxy->stats();  // atomics: read while the collision thread runs
}

// Where each tool's proxy ended: its pose belongs to the collision thread, so it is read once that
// thread has stopped (or in a stepped run, after its last step).
void HapticSession::record_proxy_ends() {
  for (auto& rig : rigs_)
    if (rig->proxy) {
      rig->report.proxy_position = rig->proxy->pose().position;
      rig->report.proxy_rotation = rig->proxy->pose().rotation;
    }
}

void HapticSession::collect_report(double seconds, bool stepped) {
  SessionReport& r = report_;
  r.stepped = stepped;
  r.seconds = seconds;
  for (auto& rig : rigs_) collect_tool_report(*rig, stepped);
  const collette::CollisionWorldStats ws = world_->stats();
  r.collision_target_hz = collision_hz_;
  r.collision_steps = ws.steps;
  r.query_median_us = ws.query_time.p50_ns * 1e-3;
  r.query_p99_us = ws.query_time.p99_ns * 1e-3;
  r.query_max_us = ws.query_time.max_ns * 1e-3;
  r.step_median_us = ws.step_time.p50_ns * 1e-3;
  r.step_p99_us = ws.step_time.p99_ns * 1e-3;
  r.step_max_us = ws.step_time.max_ns * 1e-3;
  r.objects = ws.objects;
  r.frame_bytes = ws.frame_bytes;
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
    r.collision_rate_median_hz = core::median(rates);
    r.collision_rate_mean_hz = ws.rate_hz;
  }
}

void HapticSession::publish_report() {
  report_.tools.clear();
  for (const auto& rig : rigs_) report_.tools.push_back(rig->report);
  static_cast<ToolReport&>(report_) = report_.tools.front();
}

namespace {

// force.proxy: null without one
nlohmann::json proxy_report_json(const ToolReport& r) {
  if (!r.proxy) return nullptr;
  const ToolProxyStats& p = r.proxy_stats;
  return {{"updates", p.updates},
          {"contact_updates", p.contact_updates},
          {"unsolved", p.unsolved},
          {"capped_steps", p.capped_steps},
          {"free_updates", p.free_updates},
          {"max_constraints", p.max_constraints},
          {"deepest_m", p.deepest_m},
          {"position", {r.proxy_position.x, r.proxy_position.y, r.proxy_position.z}},
          {"rotation", {r.proxy_rotation.w, r.proxy_rotation.x, r.proxy_rotation.y, r.proxy_rotation.z}},
          {"solve_us", {{"p50", p.solve_time.p50_ns * 1e-3}, {"p99", p.solve_time.p99_ns * 1e-3},
                        {"max", p.solve_time.max_ns * 1e-3}}}};
}

// a tool's part of the report: device.*, haptic.*, force.*, contact.*, energy.*
nlohmann::json tool_report_json(const ToolReport& r) {
  return {{"tool", r.tool},
          {"device",
           {{"driver", r.device.driver},
            {"name", r.device.name},
            {"model", r.device.model},
            {"serial", r.device.serial},
            {"max_force_n", r.device.max_force_n},
            {"com_rate_hz", r.device.com_rate_hz}}},
          {"haptic",
           {{"target_hz", r.haptic_target_hz},
            {"rate_hz", r.haptic_rate_hz},
            {"ticks", r.haptic_ticks},
            {"missed_deadlines", r.haptic_missed_deadlines},
            {"priority_raised", r.haptic_priority_raised},
            {"jitter_us",
             {{"p50", r.jitter_p50_us},
              {"p99", r.jitter_p99_us},
              {"p999", r.jitter_p999_us},
              {"max", r.jitter_max_us}}},
            {"tick_us", {{"p50", r.tick_p50_us}, {"p99", r.tick_p99_us}, {"max", r.tick_max_us}}}}},
          {"force",
           {{"max_n", r.force_max_n},
            {"max_torque_nm", r.torque_max_nm},
            {"max_step_n", r.force_max_step_n},
            {"max_raw_step_n", r.force_max_raw_step_n},
            {"nonfinite", r.force_nonfinite},
            {"clamped", r.force_clamped},
            {"torque_clamped", r.torque_clamped},
            {"limited",
             {{"device", r.limits.device},
              {"tool", r.limits.tool},
              {"safety", r.limits.safety},
              {"rate", r.limits.rate}}},
            {"zeroed_ticks", r.zeroed_ticks},
            {"stale_ticks", r.stale_ticks},
            {"multi_rate", r.multi_rate},
            {"tick_force", r.tick_force},
            {"model",
             {{"clamped_ticks", r.model_clamped_ticks},
              {"held_ticks", r.model_held_ticks},
              {"checked_ticks", r.model_checked_ticks},
              {"error_rms_n", r.model_error_rms_n},
              {"error_max_n", r.model_error_max_n}}},
            {"coupling", r.coupling},
            {"proxy", proxy_report_json(r)}}},
          {"contact", {{"ticks", r.contact_ticks}}},
          {"energy", {{"work_on_hand_j", r.work_on_hand_j}, {"contact_squared_speed_integral_m2_s", r.contact_squared_speed_integral}}}};
}

}  // namespace

std::string session_report_json(const SessionReport& r) {
  // the first tool's parts at the top level, as in one-tool sessions
  nlohmann::json j = tool_report_json(r);
  j.erase("tool");
  j["scene"] = r.scene;
  j["mode"] = r.stepped ? "stepped" : "threaded";
  j["seconds"] = r.seconds;
  j["stopped_early"] = r.stopped_early;
  j["collision"] = {
      {"target_hz", r.collision_target_hz},
      {"rate_hz",
       {{"min", r.collision_rate_min_hz},
        {"median", r.collision_rate_median_hz},
        {"mean", r.collision_rate_mean_hz}}},
      {"steps", r.collision_steps},
      {"query_us", {{"median", r.query_median_us}, {"p99", r.query_p99_us}, {"max", r.query_max_us}}},
      {"step_us", {{"median", r.step_median_us}, {"p99", r.step_p99_us}, {"max", r.step_max_us}}},
      {"objects", r.objects},
      {"frame_bytes", r.frame_bytes},
      {"max_pairs", r.max_pairs},
      {"truncated_frames", r.truncated_frames},
      {"coherent_queries", r.coherent_queries}};
  nlohmann::json tools = nlohmann::json::array();
  for (const ToolReport& t : r.tools) tools.push_back(tool_report_json(t));
  j["tools"] = std::move(tools);
  if (r.soft.empty()) return j.dump(2);  // a rigid scene's report is as it always was
  nlohmann::json soft = nlohmann::json::array();
  for (const SessionReport::SoftObjectReport& s : r.soft)
    soft.push_back({{"object", s.object},
                    {"tetrahedra", s.tetrahedra},
                    {"target_hz", s.target_hz},
                    {"rate_hz", s.rate_hz},
                    {"steps", s.steps},
                    {"missed_deadlines", s.missed_deadlines},
                    {"step_ms", {{"p50", s.step_p50_ms}, {"p99", s.step_p99_ms}, {"max", s.step_max_ms}}}});
  j["soft"] = std::move(soft);
  return j.dump(2);
}

}  // namespace uh::controllers
