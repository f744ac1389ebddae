#include "uh/controllers/force_controller.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "uh/core/atomic_max.hpp"

namespace uh::controllers {
namespace {

// The volume-weighted centroid of some pairs [m], the gradient of their volume with respect to
// the tool's (B's) position [m^2] and their volume [m^3], world frame.
struct PairsGeometry {
  Vec3 centroid{};
  Vec3 gradient{};
  double volume = 0.0;
};
PairsGeometry pairs_geometry(std::span<const SpherePairContact> pairs,
                             const forcecomp::PatchSelection& selection) {
  PairsGeometry g;
  Vec3 sum{};
  for (const SpherePairContact& p : pairs) {
    if (!selection.includes(p)) continue;
    const double v = static_cast<double>(p.volume);
    sum += v * Vec3{static_cast<double>(p.centroid_world[0]), static_cast<double>(p.centroid_world[1]),
                    static_cast<double>(p.centroid_world[2])};
    g.gradient -= static_cast<double>(p.area) * Vec3{static_cast<double>(p.normal_world[0]),
                                                     static_cast<double>(p.normal_world[1]),
                                                     static_cast<double>(p.normal_world[2])};
    g.volume += v;
  }
  g.centroid = g.volume > 0.0 ? sum / g.volume : Vec3{};
  return g;
}

void add(forcecomp::Wrench& sum, const forcecomp::Wrench& w) {
  sum.force += w.force;
  sum.torque += w.torque;
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
    for (PatchStage& s : w->stages) s.surface = forcecomp::SurfaceStage(*material, stage);
    w->has_surface = w->stages[0].surface.active();
  }
  watched_.push_back(std::move(w));
}

void ForceController::take_patches(Watched& w, std::span<const FrameContact> patches,
                                   const Pose& world_from_tool) {
  // where each new patch touches the tool
  Vec3 point_tool[forcecomp::kMaxContactPatches];
  std::int32_t stage_of[forcecomp::kMaxContactPatches];
  bool taken[forcecomp::kMaxContactPatches] = {};
  const std::size_t n = std::min(patches.size(), static_cast<std::size_t>(forcecomp::kMaxContactPatches));
  for (std::size_t i = 0; i < n; ++i) {
    point_tool[i] = transform_point(inverse(patches[i].world_from_tool), patches[i].volume_centroid_world);
    stage_of[i] = -1;
  }
  // greedily, the closest (patch, stage) first: a patch is the stage's when its point on the tool
  // moved less than a link distance (the contact did not jump to another region of the tool)
  for (;;) {
    double best = std::numeric_limits<double>::infinity();
    std::size_t best_i = 0;
    std::int32_t best_s = -1;
    for (std::size_t i = 0; i < n; ++i) {
      if (stage_of[i] >= 0) continue;
      for (std::int32_t k = 0; k < forcecomp::kMaxContactPatches; ++k) {
        const PatchStage& s = w.stages[k];
        if (!s.live || taken[k]) continue;
        const double d = norm(point_tool[i] - s.contact_point_tool);
        if (d < std::max(patches[i].link, s.link) && d < best) {
          best = d;
          best_i = i;
          best_s = k;
        }
      }
    }
    if (best_s < 0) break;
    stage_of[best_i] = best_s;
    taken[best_s] = true;
  }
  // stages left without a patch end their contact; new patches start a stick point in a free one
  for (std::int32_t k = 0; k < forcecomp::kMaxContactPatches; ++k) {
    PatchStage& s = w.stages[k];
    if (s.live && !taken[k]) {
      s.live = false;
      s.surface.reset();
      s.renderer.reset();
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (stage_of[i] < 0) {
      for (std::int32_t k = 0; k < forcecomp::kMaxContactPatches && stage_of[i] < 0; ++k)
        if (!w.stages[k].live) {
          stage_of[i] = k;
          w.stages[k].live = true;
          w.stages[k].contact_point_tool = point_tool[i];  // no shift: a new stick point
        }
    }
    PatchStage& s = w.stages[stage_of[i]];
    s.index = static_cast<std::int32_t>(i);
    s.link = patches[i].link;
    hold_contact_geometry(s, patches[i], world_from_tool);
  }
}

void ForceController::end_patches(Watched& w) {
  for (PatchStage& s : w.stages) {
    s.live = false;
    s.surface.reset();
    s.renderer.reset();
  }
}

void ForceController::hold_contact_geometry(PatchStage& s, const FrameContact& frame,
                                            const Pose& world_from_tool) {
  // the contact point: the patch's volume centroid, fixed on the tool until the next frame
  const Vec3 point_tool = transform_point(inverse(frame.world_from_tool), frame.volume_centroid_world);
  const Vec3 moved =
      transform_point(world_from_tool, point_tool) - transform_point(world_from_tool, s.contact_point_tool);
  s.surface.shift_contact_point(moved, frame.world_from_object);
  s.contact_point_tool = point_tool;
  s.contact_point_world_at_frame = frame.volume_centroid_world;
  // depth: a round tip of radius r pressed d in overlaps pi r d^2 through a disk of 2 pi r d, so
  // d = 2 V / |dV/dx| (a flat face gives V / |dV/dx|, half of it: the texture then reads deeper)
  const double gradient = norm(frame.volume_gradient_world);
  s.depth_at_frame_m = gradient > 0.0 ? 2.0 * frame.total_volume / gradient : 0.0;
}

forcecomp::Wrench ForceController::add_surface(const Watched& w, PatchStage& s,
                                               const forcecomp::Wrench& penalty, const Pose& world_from_tool,
                                               const forcecomp::BodyMotion& tool_motion) {
  forcecomp::ContactGeometry contact;
  contact.normal_world = normalized(penalty.force);
  contact.point_world = transform_point(world_from_tool, s.contact_point_tool);
  // the depth follows the tool between frames: moving along -n goes deeper
  contact.depth_m =
      s.depth_at_frame_m - dot(contact.normal_world, contact.point_world - s.contact_point_world_at_frame);
  contact.world_from_object = w.world_from_object;
  contact.world_from_tool = world_from_tool;
  return s.surface.apply(penalty, contact, tool_motion.center_of_mass_world).added;
}

void ForceController::bind(collette::CollisionWorld& world) {
  world_ = &world;
  collision_connection_ = world.on_collision().connect<&ForceController::on_collision>(*this);
}

void ForceController::bind(collette::CollisionWorld& world, haptico::HapticManager& manager) {
  bind(world);
  manager_ = &manager;
  // a device without motors for it ignores a torque: none is computed, counted or shown
  renders_torque_ = manager.device_info().dof_actuated == 6;
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
  FrameModels& f = w.models.write_buffer();
  const forcecomp::PenaltyInput input = w.component.penalty_input(at_frame, {}, w.coverage_product);
  const auto build = [&](const forcecomp::PatchSelection& selection) {
    forcecomp::WrenchModel m = forcecomp::build_wrench_model(
        pairs, world_from_other, world_from_tool_at_frame, input, options_.model, selection);
    m.sequence = frame.sequence;
    m.time_s = frame.time_s;
    return m;
  };
  f.whole = build({});
  f.patches = {};
  if (w.has_surface && f.whole.contact) {
    // a patch's model per patch; one patch (or pairs too shallow to place) is the whole
    f.patches = forcecomp::find_contact_patches(pairs);
    if (f.patches.count <= 1) {
      f.patches.count = 1;
      f.patch_models[0] = f.whole;
    } else {
      for (std::int32_t i = 0; i < f.patches.count; ++i) f.patch_models[i] = build({&f.patches, i});
    }
  }
  w.modelled_contact = f.whole.contact;
  w.models.publish();
}

void ForceController::on_collision(collette::ObjectId a, collette::ObjectId b, const ContactFrame& frame) {
  if (b != tool_ || !uses_model()) return;  // the tool is always B of its watchers: forces push B out of A
  if (a != ContactFrame::kEveryObject) {
    if (Watched* w = find_watched(a))
      publish_model(*w, frame, frame.sections().empty() ? nullptr : &frame.sections().front());
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
      if (!model) end_patches(*w);
      continue;
    }
    w->held.hold(frame, *section);
    w->world_from_object = section->world_from_a;
    const auto pairs = frame.pairs().subspan(static_cast<std::size_t>(section->first_pair),
                                             static_cast<std::size_t>(section->pair_count));
    if (!options_.multi_rate) {
      // held-force mode: the frame's own force, kept until the next frame
      const auto r = w->component.evaluate(pairs, tool_motion, {}, w->coverage_product);
      w->held_wrench = r.wrench;
      w->held_pairs = r.pair_count;
    }
    if (model || !w->has_surface) continue;
    // the section's patches and where each touches; one patch is the whole section (its centroid
    // the frame's when it has one section, else the pairs' own)
    w->held_patches = forcecomp::find_contact_patches(pairs);
    const std::int32_t count = std::max(w->held_patches.count, 1);
    FrameContact found[forcecomp::kMaxContactPatches];
    for (std::int32_t i = 0; i < count; ++i) {
      const forcecomp::PatchSelection selection{count > 1 ? &w->held_patches : nullptr, i};
      const PairsGeometry g = pairs_geometry(pairs, selection);
      const bool whole = count == 1;
      found[i] = {section->world_from_b,
                  section->world_from_a,
                  whole && frame.section_count == 1 ? frame.volume_centroid_world : g.centroid,
                  whole ? section->volume_gradient_world : g.gradient,
                  whole ? section->total_volume : g.volume,
                  w->held_patches.patch[i].link};
    }
    take_patches(*w, {found, static_cast<std::size_t>(count)}, world_from_tool);
    if (!options_.multi_rate) {
      // each patch's force at the frame (the held pairs at the frame's poses)
      for (PatchStage& s : w->stages)
        if (s.live)
          s.held_wrench =
              count > 1 ? w->component
                              .evaluate(w->held, section->world_from_a, section->world_from_b, tool_motion,
                                        {}, w->coverage_product, {&w->held_patches, s.index})
                              .wrench
                        : w->held_wrench;
    }
  }
}

// The period the coupling integrates over this tick [s]: a late tick must not make the proxy
// integration take one huge step (it would go unstable), so at most two nominal periods.
double ForceController::tick_period(double now) {
  const double elapsed = have_last_tick_ ? std::max(0.0, now - last_tick_s_) : 0.0;
  last_tick_s_ = now;
  have_last_tick_ = true;
  return std::min(elapsed, 2.0 * options_.coupling.period_s);
}

void ForceController::on_force(const haptico::DeviceState& state, haptico::DeviceCommand& command) {
  const double now = manager_ != nullptr ? manager_->tick_time_s() : state.time_s;
  const double dt = tick_period(now);
  const Pose world_from_handle_tool = mapping_.world_from_tool(state);
  if (options_.use_coupling && !proxy_placed_) {
    coupling_.reset(world_from_handle_tool);
    proxy_placed_ = true;
  }
  const Vec3 handle_velocity = mapping_.tool_velocity_world(state);
  const Vec3 handle_angular_velocity = mapping_.angular_velocity_world(state);
  if (proxy_ != nullptr) {
    double data_s = now;
    std::int32_t holding = 0;
    const forcecomp::Wrench spring = proxy_wrench(world_from_handle_tool, now, data_s, holding);
    finish_tick(spring, spring, now, data_s, holding, command);
    return;
  }
  const Pose world_from_tool = options_.use_coupling ? coupling_.world_from_proxy() : world_from_handle_tool;
  const forcecomp::BodyMotion tool_motion =
      component_.body_motion(world_from_tool, handle_velocity, handle_angular_velocity);
  TickSum sum{.oldest_data_s = now};
  const bool model = uses_model();
  if ((!model || options_.check_model) && world_ != nullptr) {
    // the previous frames' slots go back to the collision thread: hold the new ones where they lie
    for (const collette::WatcherId watcher : watchers_)
      if (const ContactFrame* frame = world_->take_contact(watcher))
        take_frame(*frame, world_from_tool, tool_motion);
  }
  for (auto& w : watched_) {
    if (model)
      add_modelled(*w, now, world_from_tool, tool_motion, sum);
    else
      add_held(*w, world_from_tool, tool_motion, sum);
  }
  if (model) record_model_check(sum);
  // a soft object gives under the force between its steps, as through the proxy (with_compliance),
  // the model's stiffness along the force in series with it
  if (model && !compliances_.empty() && sum.normal_stiffness > 0.0)
    sum.contact.force = with_compliance(sum.contact.force, sum.normal_stiffness, now);

  forcecomp::Wrench to_device = sum.contact;
  if (options_.use_coupling) {
    // the coupling takes the contact torque about the proxy's origin, the penalty gives it about the CoM
    forcecomp::Wrench on_proxy = sum.contact;
    on_proxy.torque += cross(tool_motion.center_of_mass_world - world_from_tool.position, sum.contact.force);
    to_device = coupling_.step(world_from_handle_tool, handle_velocity, handle_angular_velocity, on_proxy, dt)
                    .device_wrench;
  }
  finish_tick(sum.contact, to_device, now, sum.oldest_data_s, sum.pairs, command);
}

// kModel: the newest model the collision thread published for `w`, with its patches' (the
// friction and texture stages follow the patches it found)
void ForceController::take_model(Watched& w, const Pose& world_from_tool) {
  const FrameModels& f = w.models.read_buffer();
  const forcecomp::WrenchModel& m = f.whole;
  frames_received_.fetch_add(1, std::memory_order_relaxed);
  w.renderer.take(m);
  if (m.contact) w.world_from_object = m.world_from_other;
  if (!w.has_surface) return;
  if (!m.contact) {
    w.modelled_patches = 0;
    end_patches(w);
    return;
  }
  FrameContact found[forcecomp::kMaxContactPatches];
  for (std::int32_t i = 0; i < f.patches.count; ++i) {
    const forcecomp::WrenchModel& p = f.patch_models[i];
    found[i] = {p.world_from_tool,       p.world_from_other, p.volume_centroid_world,
                p.volume_gradient_world, p.total_volume,     f.patches.patch[i].link};
  }
  take_patches(w, {found, static_cast<std::size_t>(f.patches.count)}, world_from_tool);
  w.modelled_patches = f.patches.count;
  // one patch is the whole model, which w.renderer renders already
  if (f.patches.count > 1)
    for (PatchStage& s : w.stages)
      if (s.live) s.renderer.take(f.patch_models[s.index]);
}

// How stiff a local model is along the force it gives: -f^ . (dF/dx) f^ [N/L] (the penalty's force
// grows as the tool moves into the object, against f^), 0 without a force or for a model that
// softens that way.
double ForceController::stiffness_along(const forcecomp::WrenchModel& m, const Vec3& force) {
  const double magnitude = norm(force);
  if (!m.contact || !(magnitude > 0.0)) return 0.0;
  const double n[3] = {force.x / magnitude, force.y / magnitude, force.z / magnitude};
  double k = 0.0;
  for (std::size_t i = 0; i < 3; ++i)
    for (std::size_t j = 0; j < 3; ++j) k -= n[i] * m.stiffness[i][j] * n[j];
  return std::isfinite(k) ? std::max(k, 0.0) : 0.0;
}

// kModel: `w`'s force from its local model at `now`, with its patches' surface stages
void ForceController::add_modelled(Watched& w, double now, const Pose& world_from_tool,
                                   const forcecomp::BodyMotion& tool_motion, TickSum& sum) {
  if (w.models.update()) take_model(w, world_from_tool);
  if (options_.check_model && !w.held.empty())
    sum.exact_force +=
        w.component.evaluate(w.held, w.world_from_object, world_from_tool, tool_motion, {}, w.coverage_product)
            .wrench.force;
  sum.clamped += w.renderer.clamped_ticks();
  sum.held += w.renderer.held_ticks();
  if (!w.renderer.active(now)) return;
  const forcecomp::Wrench r = w.renderer.render(now, world_from_tool.rotation, tool_motion);
  const forcecomp::WrenchModel& m = w.renderer.model();
  add(sum.contact, r);
  sum.normal_stiffness += stiffness_along(m, r.force);
  // a patch's penalty: its own model's, or, for one patch, the whole one just rendered (as on the
  // held path)
  if (m.contact && w.has_surface)
    for (PatchStage& s : w.stages)
      if (s.live)
        add(sum.contact,
            add_surface(w, s,
                        w.modelled_patches > 1 ? s.renderer.render(now, world_from_tool.rotation, tool_motion) : r,
                        world_from_tool, tool_motion));
  sum.pairs += m.pair_count;
  if (m.contact) sum.oldest_data_s = std::min(sum.oldest_data_s, m.time_s);
}

// Held frames: `w`'s pairs re-evaluated at the tool's pose this tick (multi_rate) or the frame's
// force held, with its patches' surface stages
void ForceController::add_held(Watched& w, const Pose& world_from_tool, const forcecomp::BodyMotion& tool_motion,
                               TickSum& sum) {
  if (w.held.empty()) return;
  sum.oldest_data_s = std::min(sum.oldest_data_s, w.held.time_s());
  forcecomp::Wrench penalty = w.held_wrench;
  if (options_.multi_rate) {
    const auto r =
        w.component.evaluate(w.held, w.world_from_object, world_from_tool, tool_motion, {}, w.coverage_product);
    penalty = r.wrench;
    sum.pairs += r.pair_count;
  } else {
    sum.pairs += w.held_pairs;
  }
  add(sum.contact, penalty);
  if (!w.has_surface) return;
  const bool one = w.held_patches.count <= 1;
  for (PatchStage& s : w.stages) {
    if (!s.live) continue;
    // a patch's penalty: the pairs of the patch re-evaluated (or held); one patch is the whole
    const forcecomp::Wrench patch =
        one || !options_.multi_rate
            ? (one ? penalty : s.held_wrench)
            : w.component
                  .evaluate(w.held, w.world_from_object, world_from_tool, tool_motion, {}, w.coverage_product,
                            {&w.held_patches, s.index})
                  .wrench;
    add(sum.contact, add_surface(w, s, patch, world_from_tool, tool_motion));
  }
}

// kModel: the tick's model statistics, and with check_model its error against the exact force
void ForceController::record_model_check(const TickSum& sum) {
  model_clamped_ticks_.store(sum.clamped, std::memory_order_relaxed);
  model_held_ticks_.store(sum.held, std::memory_order_relaxed);
  if (!options_.check_model) return;
  const double error = norm(sum.contact.force - sum.exact_force);
  model_checked_ticks_.fetch_add(1, std::memory_order_relaxed);
  model_error_sum_sq_.store(model_error_sum_sq_.load(std::memory_order_relaxed) + error * error,
                            std::memory_order_relaxed);
  raise_max(model_error_max_n_, error);
}

forcecomp::Wrench ForceController::proxy_wrench(const Pose& world_from_handle_tool, double now, double& data_time_s,
                                                std::int32_t& holding) {
  if (const ProxyState* s = proxy_->take()) {
    proxy_state_ = *s;
    have_proxy_state_ = true;
    frames_received_.fetch_add(1, std::memory_order_relaxed);
  }
  if (!have_proxy_state_) {
    rendered_proxy_ = world_from_handle_tool;  // the tool appears at the handle (ToolProxy places it there)
    return {};
  }
  data_time_s = proxy_state_.time_s;
  holding = proxy_state_.active;
  const Pose slid = proxy_->slide(proxy_state_, world_from_handle_tool);
  const Pose proxy =
      proxy_state_.follows_handle ? slid : proxy_->towards(rendered_proxy_, slid, proxy_state_.reach_m);
  rendered_proxy_ = proxy;
  // the spring of the contact holding it (kept after release, so the spring does not stiffen
  // while the proxy catches up with the handle), never stiffer than the passivity-clamped coupling
  if (proxy_state_.active > 0 && proxy_state_.stiffness_n_m > 0.0) contact_spring_n_m_ = proxy_state_.stiffness_n_m;
  const double spring = contact_spring_n_m_ > 0.0 ? std::min(coupling_.stiffness(), contact_spring_n_m_)
                                                  : coupling_.stiffness();
  forcecomp::Wrench w;
  w.force = spring * (proxy.position - world_from_handle_tool.position);
  if (proxy_state_.active > 0 && !compliances_.empty()) w.force = with_compliance(w.force, spring, now);
  // the torque spring that goes with it, in the solver's metric (K R^2 unless the scene sets one),
  // so that one contact's torque is its r x F; within the rotational passivity bound
  if (component_.options().mode == forcecomp::ForceMode::k6Dof && renders_torque_)
    w.torque = coupling_.angular_stiffness_for(spring, proxy_->radius_m()) *
               forcecomp::rotation_vector(proxy.rotation * conjugate(world_from_handle_tool.rotation));
  return w;
}

// The proxy rests on soft objects where their last steps left them under the forces they took
// (F_i, each with its share s_i and its compliance C_i at the contact): pressed with F, each gives
// C_i (s_i F - F_i) more by its next step, and goes on moving as it moved, into the object at r_i
// along its normal n_i, for the time tau_i since that step's state came (at most a step). The spring
// k to the proxy moved so gives F = k (e - sum s_i r_i tau_i n_i) - k sum C_i (s_i F - F_i), that is
// F = (k e - k sum s_i r_i tau_i n_i + k sum C_i F_i) / (1 + k sum C_i s_i): between the steps the
// hand feels the spring in series with the object, k / (1 + k C), over a surface that keeps its
// motion, and at a step, the object having moved as foreseen, the force does not jump
// (docs/deformables.md).
Vec3 ForceController::with_compliance(const Vec3& spring_force, double spring, double now) {
  double give = 0.0;
  Vec3 taken{}, receded{};
  for (std::size_t i = 0; i < compliances_.size(); ++i) {
    LatestValue<ContactCompliance>* source = compliances_[i];
    if (source->update()) compliance_since_s_[i] = now;
    if (!source->has_value()) continue;
    const ContactCompliance& c = source->read_buffer();
    give += c.compliance_m_per_n * c.share;
    taken += c.compliance_m_per_n * c.force_world;
    const double tau = std::clamp(now - compliance_since_s_[i], 0.0, c.period_s);
    receded += (c.share * c.recede_m_per_s * tau) * c.normal_world;
  }
  return (spring_force - spring * receded + spring * taken) / (1.0 + spring * give);
}

void ForceController::finish_tick(const forcecomp::Wrench& contact, const forcecomp::Wrench& to_device, double now,
                                  double oldest_data_s, std::int32_t pairs, haptico::DeviceCommand& command) {
  const double step = norm(contact.force - last_contact_force_);
  if (std::isfinite(step)) raise_max(max_force_step_n_, step);
  last_contact_force_ = contact.force;
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
    s.model_error_rms_n = std::sqrt(model_error_sum_sq_.load(std::memory_order_relaxed) /
                                    static_cast<double>(s.model_checked_ticks));
  s.model_error_max_n = model_error_max_n_.load(std::memory_order_relaxed);
  s.safety = safety_.counters();
  return s;
}

}  // namespace uh::controllers
