#include "uh/controllers/soft_simulation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <fmt/format.h>

namespace uh::controllers {
namespace {

Vec3 unit_or_zero(const Vec3& v) { return norm(v) > 0.0 ? v / norm(v) : Vec3{}; }

std::span<const SpherePairContact> section_pairs(const ContactFrame& frame, const ContactSection& s) {
  return frame.pairs().subspan(static_cast<std::size_t>(s.first_pair), static_cast<std::size_t>(s.pair_count));
}

}  // namespace

Result<std::unique_ptr<SoftSimulation>> SoftSimulation::create(std::shared_ptr<const soft::SoftBodyModel> body,
                                                               std::shared_ptr<const collette::SphereTree> rest_tree,
                                                               const Pose& world_from_object, std::size_t tools,
                                                               const SoftTreeOptions& tree_options) {
  if (!body || !rest_tree || !rest_tree->refittable() ||
      static_cast<std::size_t>(rest_tree->leaf_count()) != body->spheres.size())
    return Error{"soft simulation: the tree is not the soft body's packing, or cannot be refitted", ErrorKind::kInvalid};
  if (!(tree_options.rebuild_distortion > 1.0) || !(tree_options.rebuild_time_share > 0.0) ||
      !(tree_options.rebuild_time_share <= 1.0) || rest_tree->arity() < 2 || rest_tree->arity() > collette::kMaxSphereTreeArity)
    return Error{fmt::format("soft simulation: rebuild_distortion {} is not above 1 or rebuild_time_share {} is not in "
                             "(0, 1], or the tree's arity {} cannot be rebuilt",
                             tree_options.rebuild_distortion, tree_options.rebuild_time_share, rest_tree->arity()),
                 ErrorKind::kInvalid};
  auto fem = soft::CorotationalFem::create(body->mesh, body->material, body->fixed);
  if (!fem) return fem.error();
  return std::unique_ptr<SoftSimulation>(
      new SoftSimulation(std::move(body), std::move(rest_tree), std::move(*fem), world_from_object, tools, tree_options));
}

SoftSimulation::SoftSimulation(std::shared_ptr<const soft::SoftBodyModel> body,
                               std::shared_ptr<const collette::SphereTree> rest_tree, soft::CorotationalFem fem,
                               const Pose& world_from_object, std::size_t tools,
                               const SoftTreeOptions& tree_options)
    : body_(std::move(body)),
      rest_tree_(std::move(rest_tree)),
      fem_(std::move(fem)),
      object_from_world_(conjugate(world_from_object.rotation)),
      tree_options_(tree_options),
      rebuild_options_{.arity = rest_tree_->arity()},
      hierarchy_(*rest_tree_),
      loads_(body_->mesh.nodes.size(), Eigen::Vector3d::Zero()),
      unit_loads_(body_->mesh.nodes.size(), Eigen::Vector3d::Zero()),
      unit_moves_(body_->mesh.nodes.size(), Eigen::Vector3d::Zero()),
      spheres_(rest_tree_->leaves().begin(), rest_tree_->leaves().end()),
      down_in_object_(rotate(object_from_world_, Vec3{0.0, 0.0, -1.0})) {
  record_.reserve(kRecordCapacity);
  // the baseline a refitted tree is measured against is this hierarchy refitted where it was
  // built: a refit's node spheres (around their children's centroid) are looser than the
  // builder's (the smallest enclosing sphere), by a quarter of the volume on a packing at rest
  hierarchy_.refit(spheres_);
  hierarchy_looseness_ = looseness(hierarchy_);
  for (std::size_t t = 0; t < tools; ++t) {
    contacts_.push_back(std::make_unique<LatestValue<SoftContacts>>());
    tool_forces_.push_back(std::make_unique<LatestValue<Vec3>>());
    compliances_.push_back(std::make_unique<LatestValue<ContactCompliance>>());
  }
  proxy_smoothing_m_.assign(tools, 0.0);
  proxy_pairs_.resize(tools);
  for (auto& slot : tree_compliances_) slot.assign(tools, ContactCompliance{});
  compliance_step_sent_.assign(tools, 0);
}

void SoftSimulation::rest_on_proxy(std::size_t tool, double smoothing_m) {
  proxy_smoothing_m_[tool] = std::max(smoothing_m, 1e-6);
  proxy_pairs_[tool].pairs.reserve(kProxyPairCapacity);
}

void SoftSimulation::post_contacts(std::size_t tool, std::int32_t object, const ContactFrame& frame) {
  // another object's own frame says nothing of this one (a tool against everything says all)
  if (frame.object_a != object && frame.object_a != ContactFrame::kEveryObject) return;
  if (proxy_smoothing_m_[tool] > 0.0) {
    keep_proxy_pairs(object, frame, proxy_pairs_[tool]);
    return;
  }
  SoftContacts& out = contacts_[tool]->write_buffer();
  out.count = 0;
  out.share = 0.0;
  out.normal_world = {};
  std::span<const SpherePairContact> pairs;
  if (frame.object_a == object) {
    pairs = frame.pairs();
    out.share = 1.0;
  } else {
    for (const ContactSection& s : frame.sections()) {
      if (s.object_a != object) continue;
      pairs = section_pairs(frame, s);
      out.share = frame.total_volume > 0.0 ? s.total_volume / frame.total_volume : 0.0;
    }
  }
  Vec3 normal{};
  for (const SpherePairContact& p : pairs) {
    if (out.count == SoftContacts::kCapacity) break;
    if (!(p.volume > 0.f) || p.leaf_a < 0 || static_cast<std::size_t>(p.leaf_a) >= body_->spheres.size()) continue;
    out.leaves[static_cast<std::size_t>(out.count)] = p.leaf_a;
    out.weights[static_cast<std::size_t>(out.count)] = p.volume;
    ++out.count;
    normal += static_cast<double>(p.volume) * Vec3{static_cast<double>(p.normal_world[0]),
                                                   static_cast<double>(p.normal_world[1]),
                                                   static_cast<double>(p.normal_world[2])};
  }
  out.normal_world = unit_or_zero(normal);
  contacts_[tool]->publish();
}

void SoftSimulation::hand_over_compliance(std::size_t tool) {
  // the tree the collision step took (0: still the rest tree, no step's compliance yet)
  const ContactCompliance& rested_on = tree_compliances_[trees_.read_slot()][tool];
  if (rested_on.step != compliance_step_sent_[tool]) {
    compliances_[tool]->write(rested_on);
    compliance_step_sent_[tool] = rested_on.step;
  }
}

void SoftSimulation::rest_proxy_at(std::size_t tool, const Pose& world_from_proxy) {
  if (!(proxy_smoothing_m_[tool] > 0.0)) return;
  hand_over_compliance(tool);
  ProxyPairs& frame = proxy_pairs_[tool];
  if (!frame.posted) return;
  frame.posted = false;
  weigh_by_nearness(proxy_smoothing_m_[tool], frame, world_from_proxy, contacts_[tool]->write_buffer());
  contacts_[tool]->publish();
}

// A proxy's frame, kept as its spheres: the object's where the query had it (it does not move
// before the next query), the tool's in its own frame, to be placed where the proxy moves to.
void SoftSimulation::keep_proxy_pairs(std::int32_t object, const ContactFrame& frame, ProxyPairs& out) const {
  const auto centre = [](const Sphere& x) {
    return Vec3{static_cast<double>(x.x), static_cast<double>(x.y), static_cast<double>(x.z)};
  };
  out.posted = true;
  out.pairs.clear();  // keeps its capacity: the pushes below never allocate
  for (const ContactSection& s : frame.sections())
    for (const SpherePairContact& p : section_pairs(frame, s)) {
      if (out.pairs.size() == kProxyPairCapacity) return;
      out.pairs.push_back({.object_centre_world = transform_point(s.world_from_a, centre(p.sphere_a_local)),
                           .tool_centre_local = centre(p.sphere_b_local),
                           .radii = static_cast<double>(p.sphere_a_local.radius) +
                                    static_cast<double>(p.sphere_b_local.radius),
                           .leaf = p.leaf_a,
                           .this_object = s.object_a == object});
    }
}

// Through a proxy: the proxy rests on the soft minimum of its pairs' gaps (ToolProxy), whose
// gradient gives each pair exp(-gap / e) over the sum, so each pair takes that share of the force
// holding the proxy, at the pose the proxy rests at (where the spring the tool feels pulls it). A
// pair more than 7 e (1.4 mm at e = 0.2 mm) farther than the nearest takes under 0.1 % of the
// nearest's and is left out, so the buffer holds those that matter. The object's share is its
// pairs' weight over the frame's.
void SoftSimulation::weigh_by_nearness(double smoothing_m, ProxyPairs& frame, const Pose& world_from_proxy,
                                       SoftContacts& out) const {
  constexpr double kLeftOut = 1e-3;
  double nearest = std::numeric_limits<double>::infinity();
  for (ProxyPair& p : frame.pairs) {
    p.gap = norm(transform_point(world_from_proxy, p.tool_centre_local) - p.object_centre_world) - p.radii;
    nearest = std::min(nearest, p.gap);
  }
  out.count = 0;
  double all = 0.0, mine = 0.0;
  Vec3 normal{};
  for (const ProxyPair& p : frame.pairs) {
    const double w = std::exp(-(p.gap - nearest) / smoothing_m);
    all += w;
    if (!p.this_object) continue;
    mine += w;
    if (w < kLeftOut || out.count == SoftContacts::kCapacity || p.leaf < 0 ||
        static_cast<std::size_t>(p.leaf) >= body_->spheres.size())
      continue;
    out.leaves[static_cast<std::size_t>(out.count)] = p.leaf;
    out.weights[static_cast<std::size_t>(out.count)] = static_cast<float>(w);
    ++out.count;
    // from the object's sphere to the tool's
    normal += w * unit_or_zero(transform_point(world_from_proxy, p.tool_centre_local) - p.object_centre_world);
  }
  out.share = all > 0.0 ? mine / all : 0.0;
  out.normal_world = unit_or_zero(normal);
}

void SoftSimulation::post_tool_force(std::size_t tool, const Vec3& force_world) { tool_forces_[tool]->write(force_world); }

// `force_world` (a load on the object) over tool `tool`'s contact spheres by their weights, and
// each sphere's part to its tetrahedron's nodes, added to `loads`; false when it has no contact.
bool SoftSimulation::spread_tool_force(std::size_t tool, const Vec3& force_world,
                                       std::vector<Eigen::Vector3d>& loads) const {
  const SoftContacts& c = contacts_[tool]->read_buffer();
  double total = 0.0;
  for (std::int32_t i = 0; i < c.count; ++i) total += static_cast<double>(c.weights[static_cast<std::size_t>(i)]);
  if (!(total > 0.0)) return false;
  const Vec3 f = rotate(object_from_world_, force_world) / total;
  const Eigen::Vector3d per_weight(f.x, f.y, f.z);
  for (std::int32_t i = 0; i < c.count; ++i) {
    const auto k = static_cast<std::size_t>(i);
    soft::spread_sphere_force(*body_, c.leaves[k], static_cast<double>(c.weights[k]) * per_weight, loads);
  }
  return true;
}

// Each tool's felt force, this object's share of it, back on the object's contact spheres with
// the opposite sign (spread_tool_force): the loads sum to minus what the tools felt.
void SoftSimulation::gather_loads() {
  std::fill(loads_.begin(), loads_.end(), Eigen::Vector3d::Zero());
  for (std::size_t t = 0; t < contacts_.size(); ++t) {
    contacts_[t]->update();
    tool_forces_[t]->update();
    if (tool_forces_[t]->has_value())
      spread_tool_force(t, tool_forces_[t]->read_buffer() * -contacts_[t]->read_buffer().share, loads_);
  }
}

// For each tool, the force this step took and how far its contact will move per newton more
// in the next one: a unit load into the object along the contact's normal, spread as the step's
// loads, through the step's system (CorotationalFem::step_response); the load-weighted mean of the
// moves along it. Known from the first step in contact, before any force is felt, so the first
// touch is soft too. Kept beside the tree the step publishes (hand_over_compliance hands it over).
Status SoftSimulation::find_compliances(double dt_s) {
  std::vector<ContactCompliance>& beside_tree = tree_compliances_[trees_.write_slot()];
  for (std::size_t t = 0; t < compliances_.size(); ++t) {
    ContactCompliance& out = beside_tree[t];
    out = {.step = steps_ + 1};
    const SoftContacts& contacts = contacts_[t]->read_buffer();
    std::fill(unit_loads_.begin(), unit_loads_.end(), Eigen::Vector3d::Zero());
    if (contacts.share > 0.0 && spread_tool_force(t, contacts.normal_world * -1.0, unit_loads_)) {
      if (Status s = fem_.step_response(unit_loads_, unit_moves_); !s) return s;
      double compliance = 0.0;
      for (std::size_t n = 0; n < unit_loads_.size(); ++n) compliance += unit_loads_[n].dot(unit_moves_[n]);
      // the unit loads push into the object with weights summing to 1: their work on the nodes'
      // velocities is the contact's mean speed into the object
      double recede = 0.0;
      for (std::size_t n = 0; n < unit_loads_.size(); ++n) recede += unit_loads_[n].dot(fem_.velocities()[n]);
      const Vec3 felt = tool_forces_[t]->has_value() ? tool_forces_[t]->read_buffer() : Vec3{};
      out = {.force_world = felt * contacts.share,
             .share = contacts.share,
             // the haptic thread divides by 1 + k C: never negative, never a NaN
             .compliance_m_per_n = std::isfinite(compliance) ? std::max(compliance, 0.0) : 0.0,
             .normal_world = contacts.normal_world,
             .recede_m_per_s = std::isfinite(recede) ? recede : 0.0,
             .period_s = dt_s,
             .step = steps_ + 1};
    }
  }
  return Ok{};
}

Status SoftSimulation::step(double dt_s) {
  if (fail_next_step_.exchange(false, std::memory_order_relaxed))
    return Error{"the step was made to fail (fail_next_step)", ErrorKind::kThread};
  if (rotation_in_.update()) {  // moved: the world's forces and its down turn into the object's frame anew
    object_from_world_ = conjugate(rotation_in_.read_buffer());
    down_in_object_ = rotate(object_from_world_, Vec3{0.0, 0.0, -1.0});
  }
  gather_loads();
  if (Status s = fem_.step(dt_s, loads_); !s) return s;
  if (Status s = find_compliances(dt_s); !s) return s;
  soft::deform_spheres(*body_, fem_.positions(), spheres_);
  if (Status s = refit_or_rebuild(trees_.write_buffer()); !s) return s;
  trees_.publish();
  publish_surface(dt_s);
  return Ok{};
}

// The looseness of a tree of this object at the FEM's positions: the volume of its node spheres
// just above the leaves over the object's volume (the lattice's); 0 when that volume is not
// positive (elements turned inside out: nothing to measure). The node spheres' volume is what a
// refit loosens and what the builder's cuts keep small (it decides how many node pairs a query
// visits); over the object's volume, so that a squashed object, whose regrouped tree would be
// smaller, counts as distorted too (its refitted spheres keep their rest size). A sum rather than
// the worst node: a press dents a few nodes, which a rebuild would not help, while a whole region
// sheared, twisted or squashed loosens many. Computed from the refit's own sum
// (SphereTree::leaf_parent_volume) and one pass over the tetrahedra, not the leaves.
double SoftSimulation::looseness(const collette::SphereTree& tree) const {
  const double volume = soft::mesh_volume(body_->mesh, fem_.positions());
  return volume > 0.0 ? tree.leaf_parent_volume() / volume : 0.0;
}

// The generation of the hierarchy that `slot` (one of trees_' three) holds.
std::uint64_t& SoftSimulation::hierarchy_of(const collette::SphereTree& slot) {
  for (SlotHierarchy& s : slot_hierarchies_)
    if (s.slot == &slot || s.slot == nullptr) {
      s.slot = &slot;
      return s.generation;
    }
  // a triple buffer has three slots: never reached; a fourth would take the hierarchy every time
  unknown_slot_generation_ = 0;
  return unknown_slot_generation_;
}

// The worker's tree (a copy of a refitted slot, rebuilt where its leaves were) and how it went.
struct SoftSimulation::BackgroundRebuild {
  collette::SphereTree tree;
  collette::SphereTreeBuildOptions options;
  Status outcome = Ok{};
  std::chrono::steady_clock::duration took{};
  BackgroundWorker worker{[this] {
    const auto started = std::chrono::steady_clock::now();
    outcome = collette::rebuild_sphere_tree(tree, options);
    took = std::chrono::steady_clock::now() - started;
    return static_cast<bool>(outcome);
  }};  // last: its thread reads the members above
};

// Refits `slot` (the write buffer) over the step's spheres, first copying the current hierarchy
// into it if it holds an older one (or none: a slot's first turn); when the refit has grown too
// loose, rebuilds the hierarchy (in place, or asks the worker) and makes the rebuilt one the
// current one for every slot.
Status SoftSimulation::refit_or_rebuild(collette::SphereTree& slot) {
  if (Status s = take_rebuilt_hierarchy(); !s) return s;
  std::uint64_t& generation = hierarchy_of(slot);
  if (generation != hierarchy_generation_) {
    slot = hierarchy_;  // into the slot's own storage, sized on its first turn
    generation = hierarchy_generation_;
  }
  slot.refit(spheres_);
  const double now = looseness(slot);
  if (!(now > 0.0)) return Ok{};  // no volume to measure against: the last distortion stands
  tree_distortion_ = now / hierarchy_looseness_;
  if (!(tree_distortion_ > tree_options_.rebuild_distortion)) return Ok{};
  if (std::chrono::steady_clock::now() < next_rebuild_) return Ok{};
  if (!background_rebuild_) return rebuild_in_place(slot);
  BackgroundRebuild& b = *background_rebuild_;
  b.worker.request([&] { b.tree = slot; });  // busy: one is under way already
  return Ok{};
}

Status SoftSimulation::rebuild_in_place(collette::SphereTree& slot) {
  const auto started = std::chrono::steady_clock::now();
  if (Status s = collette::rebuild_sphere_tree(slot, rebuild_options_); !s) return s;
  hierarchy_ = slot;
  adopt_hierarchy(std::chrono::steady_clock::now() - started);
  hierarchy_of(slot) = hierarchy_generation_;
  tree_distortion_ = looseness(slot) / hierarchy_looseness_;
  return Ok{};
}

// The worker's rebuilt hierarchy, once it is done, becomes the current one (each slot takes it on
// its next turn); it groups the same leaves, so it is refitted where they are now.
Status SoftSimulation::take_rebuilt_hierarchy() {
  if (!background_rebuild_) return Ok{};
  BackgroundRebuild& b = *background_rebuild_;
  switch (b.worker.take([&] { std::swap(hierarchy_, b.tree); })) {
    case BackgroundWorker::Taken::kNothing:
      return Ok{};
    case BackgroundWorker::Taken::kFailed:
      return b.outcome;
    case BackgroundWorker::Taken::kDone:
      break;
  }
  adopt_hierarchy(b.took);
  return Ok{};
}

// hierarchy_ (rebuilt, which took `took`) is the current one: a new generation, its baseline
// looseness refitted where the spheres are (as at construction), the next rebuild not before the
// time share allows
void SoftSimulation::adopt_hierarchy(std::chrono::steady_clock::duration took) {
  next_rebuild_ = std::chrono::steady_clock::now() +
                  std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                      took * (1.0 / tree_options_.rebuild_time_share - 1.0));
  ++hierarchy_generation_;
  hierarchy_.refit(spheres_);
  hierarchy_looseness_ = looseness(hierarchy_);
  ++tree_rebuilds_;
}

SoftSimulation::~SoftSimulation() { stop(); }

void SoftSimulation::work_in_background(bool on) {
  fem_.factorise_in_background(on);
  fem_.assemble_on_two_threads(on);
  if (!on) {
    background_rebuild_.reset();
  } else if (!background_rebuild_) {
    background_rebuild_ = std::make_unique<BackgroundRebuild>();
    background_rebuild_->options = rebuild_options_;
  }
}

void SoftSimulation::publish_surface(double dt_s) {
  SoftSurface& surface = surfaces_.write_buffer();
  // a slot's storage is sized the first time it comes round, as the trees' are
  surface.xyz.resize(3 * surface_vertex_count());
  soft::deform_surface(*body_, fem_.positions(), surface.xyz);
  surface.step = ++steps_;
  record_step(dt_s, surface.xyz);
  surfaces_.publish();
}

void SoftSimulation::record_step(double dt_s, std::span<const float> xyz) {
  if (record_.size() == record_.capacity()) return;  // full: no allocation on this thread
  const auto& rest = body_->surface.vertices;
  double deepest = 0.0;
  for (std::size_t i = 0; i < rest.size(); ++i) {
    const Vec3 moved{static_cast<double>(xyz[3 * i]) - rest[i].x(), static_cast<double>(xyz[3 * i + 1]) - rest[i].y(),
                     static_cast<double>(xyz[3 * i + 2]) - rest[i].z()};
    deepest = std::max(deepest, dot(moved, down_in_object_));
  }
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  for (const auto& l : loads_) total += l;
  record_.push_back({.time_s = static_cast<double>(steps_) * dt_s,
                     .indentation_m = deepest,
                     .force_n = total.norm(),
                     .tree_distortion = tree_distortion_});
}

std::uint64_t SoftSimulation::read_surface(std::span<float> xyz) {
  const std::lock_guard lock(surface_readers_);
  surfaces_.update();
  const SoftSurface& newest = surfaces_.read_buffer();
  if (newest.step == 0) {  // no step yet: the rest surface
    soft::deform_surface(*body_, body_->mesh.nodes, xyz);
    return 0;
  }
  const std::size_t n = std::min(xyz.size() / 3 * 3, newest.xyz.size());
  std::copy_n(newest.xyz.begin(), n, xyz.begin());
  return newest.step;
}

Status SoftSimulation::start(double rate_hz, std::function<void()> on_failure) {
  // no spinning before each deadline: the simulation shares the machine's cores with the haptic
  // and collision threads, and a millisecond late is nothing at its rate
  // a step is a fixed stretch of the simulation's time: steps late after a slow one (preempted,
  // or its iterations longer) run back to back until on the grid again, so the simulation keeps
  // time with the clock; only when it falls 20 steps (100 ms at 200 Hz) behind does it skip them
  loop_ = std::make_unique<FixedRateLoop>(FixedRateLoopOptions{
      .rate_hz = rate_hz, .spin_us = 0.0, .name = "uh-soft", .catch_up_periods = kCatchUpSteps});
  // a factorisation or a rebuild in place takes several periods at a few thousand tetrahedra: on
  // a worker the steps go on meanwhile (stepped runs, which must repeat exactly, never start this)
  work_in_background(true);
  const double dt_s = 1.0 / rate_hz;
  return loop_->start([this, dt_s, on_failure = std::move(on_failure)](const TickInfo&) {
    // a fixed step whatever the tick's lateness: the simulation's time is its own
    if (Status s = step(dt_s); !s) {
      if (on_failure) on_failure();
      failure_ = s;
      loop_->request_stop();
    }
  });
}

void SoftSimulation::stop() {
  if (!loop_) return;
  loop_->stop();
  work_in_background(false);  // the loop has ended: nothing steps any more
}

}  // namespace uh::controllers
