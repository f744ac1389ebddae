#include "uh/controllers/force_controller.hpp"

#include <algorithm>
#include <cmath>

namespace uh::controllers {
namespace {

// The volume-weighted centroid of one section's pairs [m, world frame].
Vec3 section_centroid(const ContactFrame& frame, const ContactSection& section) {
  Vec3 sum{};
  double volume = 0.0;
  for (const SpherePairContact& p : frame.pairs().subspan(static_cast<std::size_t>(section.first_pair),
                                                          static_cast<std::size_t>(section.pair_count))) {
    const double v = static_cast<double>(p.volume);
    sum += v * Vec3{static_cast<double>(p.centroid_world[0]), static_cast<double>(p.centroid_world[1]),
                    static_cast<double>(p.centroid_world[2])};
    volume += v;
  }
  return volume > 0.0 ? sum / volume : Vec3{};
}

// Raises an atomic maximum written by one thread (the haptic thread) and read by others.
void raise_max(std::atomic<double>& max, double value) {
  if (value > max.load(std::memory_order_relaxed)) max.store(value, std::memory_order_relaxed);
}

}  // namespace

ForceController::ForceController(collette::ObjectId tool, const forcecomp::ForceComponent& tool_component,
                                 const WorkspaceMapping& mapping, const ForceControllerOptions& options)
    : tool_(tool),
      component_(tool_component),
      mapping_(mapping),
      options_(options),
      safety_(options.safety),
      coupling_(options.coupling) {}

ForceController::~ForceController() = default;

void ForceController::add_watched(collette::ObjectId object, double coverage_product,
                                  const forcecomp::ContactMaterial* material,
                                  const forcecomp::SurfaceStageOptions& surface) {
  auto w = std::make_unique<Watched>(options_.model);
  w->object = object;
  w->coverage_product = coverage_product;
  w->component = component_;
  if (material != nullptr) {
    forcecomp::ForceComponentOptions options = component_.options();
    options.params.stiffness = material->stiffness;
    options.params.damping = material->damping;
    w->component = forcecomp::ForceComponent(options);
    forcecomp::SurfaceStageOptions stage = surface;
    stage.mode = options.mode;
    w->surface = forcecomp::SurfaceStage(*material, stage);
  }
  watched_.push_back(std::move(w));
}

void ForceController::hold_contact_geometry(Watched& w, const FrameContact& frame,
                                            const Pose& world_from_tool) {
  if (!w.surface.active()) return;
  // the contact point: the overlap's volume centroid, fixed on the tool until the next frame
  const Vec3 point_tool = transform_point(inverse(frame.world_from_tool), frame.volume_centroid_world);
  const Vec3 moved =
      transform_point(world_from_tool, point_tool) - transform_point(world_from_tool, w.contact_point_tool);
  w.surface.shift_contact_point(moved, frame.world_from_object);
  w.contact_point_tool = point_tool;
  w.contact_point_world_at_frame = frame.volume_centroid_world;
  // depth: a round tip of radius r pressed d in overlaps pi r d^2 through a disk of 2 pi r d, so
  // d = 2 V / |dV/dx| (a flat face gives V / |dV/dx|, half of it: the texture then reads deeper)
  const double gradient = norm(frame.volume_gradient_world);
  w.depth_at_frame_m = gradient > 0.0 ? 2.0 * frame.total_volume / gradient : 0.0;
}

forcecomp::Wrench ForceController::add_surface(Watched& w, const forcecomp::Wrench& penalty,
                                               const Pose& world_from_tool,
                                               const forcecomp::BodyMotion& tool_motion) {
  if (!w.surface.active()) return penalty;
  forcecomp::ContactGeometry contact;
  contact.normal_world = normalized(penalty.force);
  contact.point_world = transform_point(world_from_tool, w.contact_point_tool);
  // the depth follows the tool between frames: moving along -n goes deeper
  contact.depth_m =
      w.depth_at_frame_m - dot(contact.normal_world, contact.point_world - w.contact_point_world_at_frame);
  contact.world_from_object = w.world_from_object;
  contact.world_from_tool = world_from_tool;
  return w.surface.apply(penalty, contact, tool_motion.center_of_mass_world).wrench;
}

void ForceController::bind(collette::CollisionWorld& world, haptico::HapticManager& manager) {
  world_ = &world;
  manager_ = &manager;
  collision_connection_ = world.on_collision().connect<&ForceController::on_collision>(*this);
  force_connection_ = manager.force_on_haptic_tick().connect<&ForceController::on_force>(*this);
}

ForceController::Watched* ForceController::find_watched(collette::ObjectId object) {
  for (auto& w : watched_)
    if (w->object == object) return w.get();
  return nullptr;
}

// Collision thread: the model of one object's section of a frame (null: no contact with it).
void ForceController::publish_model(Watched& w, const ContactFrame& frame, const ContactSection* section) {
  const Pose world_from_other = section != nullptr ? section->world_from_a : frame.world_from_a;
  const Pose world_from_tool_at_frame = section != nullptr ? section->world_from_b : frame.world_from_b;
  // the model is built here, on the collision thread, around the tool pose the query used
  const Pose& world_from_tool =
      component_.options().side == forcecomp::ContactSide::kB ? world_from_tool_at_frame : world_from_other;
  const forcecomp::BodyMotion at_frame = w.component.body_motion(world_from_tool, {}, {});
  const auto pairs = section != nullptr ? frame.pairs().subspan(static_cast<std::size_t>(section->first_pair),
                                                                static_cast<std::size_t>(section->pair_count))
                                        : std::span<const SpherePairContact>{};
  forcecomp::WrenchModel& m = w.models.write_buffer();
  m = forcecomp::build_wrench_model(pairs, world_from_other, world_from_tool_at_frame,
                                    w.component.penalty_input(at_frame, {}, w.coverage_product), options_.model);
  m.sequence = frame.sequence;
  m.time_s = frame.time_s;
  w.modelled_contact = m.contact;
  w.models.publish();
}

void ForceController::on_collision(collette::ObjectId a, collette::ObjectId b, const ContactFrame& frame) {
  if (b != tool_ || !uses_model()) return;  // the tool is always B of its watchers: forces push B out of A
  if (a != ContactFrame::kEveryObject) {
    if (Watched* w = find_watched(a)) publish_model(*w, frame, frame.sections().empty() ? nullptr : &frame.sections().front());
    return;
  }
  // the tool against everything: a model per touched object, and one without contact for each
  // watched object the tool just left
  for (auto& w : watched_) w->in_frame = false;
  for (const ContactSection& s : frame.sections()) {
    Watched* w = find_watched(s.object_a);
    if (w == nullptr) continue;
    w->in_frame = true;
    publish_model(*w, frame, &s);
  }
  for (auto& w : watched_)
    if (!w->in_frame && w->modelled_contact) publish_model(*w, frame, nullptr);
}

// Haptic thread: holds each watched object's part of a new frame where it lies.
void ForceController::take_frame(const ContactFrame& frame, const Pose& world_from_tool,
                                 const forcecomp::BodyMotion& tool_motion) {
  const bool model = uses_model();
  if (!model) frames_received_.fetch_add(1, std::memory_order_relaxed);
  const bool every = frame.object_a == ContactFrame::kEveryObject;
  for (auto& w : watched_) {
    if (!every && w->object != frame.object_a) continue;
    const ContactSection* section = nullptr;
    for (const ContactSection& s : frame.sections())
      if (s.object_a == w->object) section = &s;
    if (section == nullptr || section->pair_count == 0) {
      w->held.clear();
      w->held_wrench = {};
      w->held_pairs = 0;
      if (!model) w->surface.reset();
      continue;
    }
    w->held.hold(frame, *section);
    w->world_from_object = section->world_from_a;
    if (!model) {
      // the section's centroid: the frame's when it has one section, else the pairs' own
      const Vec3 centroid = frame.section_count == 1 ? frame.volume_centroid_world : section_centroid(frame, *section);
      hold_contact_geometry(*w,
                            {section->world_from_b, section->world_from_a, centroid, section->volume_gradient_world,
                             section->total_volume},
                            world_from_tool);
    }
    if (!options_.multi_rate) {
      // held-force mode: the frame's own force, kept until the next frame
      const auto r = w->component.evaluate(frame.pairs().subspan(static_cast<std::size_t>(section->first_pair),
                                                                 static_cast<std::size_t>(section->pair_count)),
                                           tool_motion, {}, w->coverage_product);
      w->held_wrench = r.wrench;
      w->held_pairs = r.pair_count;
    }
  }
}

void ForceController::on_force(const haptico::DeviceState& state, haptico::DeviceCommand& command) {
  const double now = manager_ != nullptr ? manager_->tick_time_s() : state.time_s;
  // a late tick must not make the proxy integration take one huge step (it would go unstable):
  // integrate at most two nominal periods per tick
  const double elapsed = have_last_tick_ ? std::max(0.0, now - last_tick_s_) : 0.0;
  const double dt = std::min(elapsed, 2.0 * options_.coupling.period_s);
  last_tick_s_ = now;
  have_last_tick_ = true;

  const Pose world_from_handle_tool = mapping_.world_from_tool(state);
  if (options_.use_coupling && !proxy_placed_) {
    coupling_.reset(world_from_handle_tool);
    proxy_placed_ = true;
  }
  const Vec3 handle_velocity = mapping_.tool_velocity_world(state);
  const Vec3 handle_angular_velocity = mapping_.angular_velocity_world(state);
  const Pose world_from_tool = options_.use_coupling ? coupling_.world_from_proxy() : world_from_handle_tool;
  const forcecomp::BodyMotion tool_motion =
      component_.body_motion(world_from_tool, handle_velocity, handle_angular_velocity);

  forcecomp::Wrench contact{};
  std::int32_t pairs = 0;
  double oldest_data_s = now;
  const bool model = uses_model();
  Vec3 exact_force{};  // check_model: the exact re-evaluation's force, beside the model's
  std::uint64_t clamped = 0, held = 0;
  if ((!model || options_.check_model) && world_ != nullptr) {
    // the previous frames' slots go back to the collision thread: hold the new ones where they lie
    for (const collette::WatcherId watcher : watchers_)
      if (const ContactFrame* frame = world_->take_contact(watcher)) take_frame(*frame, world_from_tool, tool_motion);
  }
  for (auto& w : watched_) {
    if (model) {
      if (w->models.update()) {
        const forcecomp::WrenchModel& m = w->models.read_buffer();
        frames_received_.fetch_add(1, std::memory_order_relaxed);
        w->renderer.take(m);
        if (m.contact) {
          w->world_from_object = m.world_from_other;
          hold_contact_geometry(*w,
                                {m.world_from_tool, m.world_from_other, m.volume_centroid_world,
                                 m.volume_gradient_world, m.total_volume},
                                world_from_tool);
        } else {
          w->surface.reset();
        }
      }
      if (options_.check_model && !w->held.empty())
        exact_force += w->component
                           .evaluate(w->held, w->world_from_object, world_from_tool, tool_motion, {},
                                     w->coverage_product)
                           .wrench.force;
      clamped += w->renderer.clamped_ticks();
      held += w->renderer.held_ticks();
      if (!w->renderer.active(now)) continue;
      const forcecomp::Wrench r = w->renderer.render(now, world_from_tool.rotation, tool_motion);
      const forcecomp::WrenchModel& m = w->renderer.model();
      const forcecomp::Wrench felt = m.contact ? add_surface(*w, r, world_from_tool, tool_motion) : r;
      contact.force += felt.force;
      contact.torque += felt.torque;
      pairs += m.pair_count;
      if (m.contact) oldest_data_s = std::min(oldest_data_s, m.time_s);
      continue;
    }
    if (w->held.empty()) continue;
    oldest_data_s = std::min(oldest_data_s, w->held.time_s());
    if (options_.multi_rate) {
      const auto r = w->component.evaluate(w->held, w->world_from_object, world_from_tool, tool_motion, {},
                                           w->coverage_product);
      const forcecomp::Wrench felt = add_surface(*w, r.wrench, world_from_tool, tool_motion);
      contact.force += felt.force;
      contact.torque += felt.torque;
      pairs += r.pair_count;
    } else {
      const forcecomp::Wrench felt = add_surface(*w, w->held_wrench, world_from_tool, tool_motion);
      contact.force += felt.force;
      contact.torque += felt.torque;
      pairs += w->held_pairs;
    }
  }

  if (model) {
    model_clamped_ticks_.store(clamped, std::memory_order_relaxed);
    model_held_ticks_.store(held, std::memory_order_relaxed);
    if (options_.check_model) {
      const double error = norm(contact.force - exact_force);
      model_checked_ticks_.fetch_add(1, std::memory_order_relaxed);
      model_error_sum_sq_.store(model_error_sum_sq_.load(std::memory_order_relaxed) + error * error,
                                std::memory_order_relaxed);
      raise_max(model_error_max_n_, error);
    }
  }

  const double step = norm(contact.force - last_contact_force_);
  if (std::isfinite(step)) raise_max(max_force_step_n_, step);
  last_contact_force_ = contact.force;

  forcecomp::Wrench to_device = contact;
  if (options_.use_coupling) {
    // the coupling takes the contact torque about the proxy's origin, the penalty gives it about the CoM
    forcecomp::Wrench on_proxy = contact;
    on_proxy.torque += cross(tool_motion.center_of_mass_world - world_from_tool.position, contact.force);
    to_device = coupling_.step(world_from_handle_tool, handle_velocity, handle_angular_velocity, on_proxy, dt)
                    .device_wrench;
  }
  const forcecomp::Wrench safe = safety_.apply(to_device, now, oldest_data_s);
  const Vec3 force_device = mapping_.to_device(safe.force);
  const Vec3 torque_device = mapping_.to_device(safe.torque);
  command.force += force_device;
  command.torque += torque_device;

  ticks_.fetch_add(1, std::memory_order_relaxed);
  if (pairs > 0) contact_ticks_.fetch_add(1, std::memory_order_relaxed);
  const double force_n = norm(force_device);
  raise_max(max_force_n_, force_n);
  raise_max(max_torque_nm_, norm(torque_device));
  last_force_n_.store(force_n, std::memory_order_relaxed);
  last_pairs_.store(pairs, std::memory_order_relaxed);
}

ForceControllerStats ForceController::stats() const {
  ForceControllerStats s;
  s.ticks = ticks_.load(std::memory_order_relaxed);
  s.contact_ticks = contact_ticks_.load(std::memory_order_relaxed);
  s.frames_received = frames_received_.load(std::memory_order_relaxed);
  s.max_force_n = max_force_n_.load(std::memory_order_relaxed);
  s.max_torque_nm = max_torque_nm_.load(std::memory_order_relaxed);
  s.max_force_step_n = max_force_step_n_.load(std::memory_order_relaxed);
  s.last_force_n = last_force_n_.load(std::memory_order_relaxed);
  s.last_pairs = last_pairs_.load(std::memory_order_relaxed);
  s.model_clamped_ticks = model_clamped_ticks_.load(std::memory_order_relaxed);
  s.model_held_ticks = model_held_ticks_.load(std::memory_order_relaxed);
  s.model_checked_ticks = model_checked_ticks_.load(std::memory_order_relaxed);
  if (s.model_checked_ticks > 0)
    s.model_error_rms_n =
        std::sqrt(model_error_sum_sq_.load(std::memory_order_relaxed) / static_cast<double>(s.model_checked_ticks));
  s.model_error_max_n = model_error_max_n_.load(std::memory_order_relaxed);
  s.safety = safety_.counters();
  return s;
}

}  // namespace uh::controllers
