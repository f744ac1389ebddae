#include "uh/collette/collision_world.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include <fmt/format.h>

namespace uh::collette {
namespace {

constexpr int kSlotBits = 16;
constexpr std::uint32_t kSlotMask = (1u << kSlotBits) - 1u;
constexpr std::uint32_t kGenerationMask = (1u << (31 - kSlotBits)) - 1u;  // ids stay non-negative

std::int32_t make_id(std::int32_t slot, std::uint32_t generation) {
  return static_cast<std::int32_t>((generation << kSlotBits) | static_cast<std::uint32_t>(slot));
}
std::int32_t slot_of(std::int32_t id) {
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(id) & kSlotMask);
}
std::uint32_t generation_of(std::int32_t id) { return static_cast<std::uint32_t>(id) >> kSlotBits; }
core::SlotId slot_id(std::int32_t id) { return {static_cast<std::uint32_t>(slot_of(id)), generation_of(id)}; }

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::uint64_t elapsed_ns(std::chrono::steady_clock::time_point since) {
  return static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - since).count());
}

Vec3 to_vec(const SphereTreeNode& n) {
  return {static_cast<double>(n.x), static_cast<double>(n.y), static_cast<double>(n.z)};
}

}  // namespace

struct CollisionWorld::Object {
  ObjectId id = -1;
  std::shared_ptr<const SphereTree> tree;
  LatestValue<SphereTree>* deformed_trees = nullptr;  // a soft body's, newest taken each step
  const SphereTree* now = nullptr;  // the tree queried: `tree`, or the newest deformed one (collision thread)
  std::string name;
  double coverage = 1.0;
  double extra_margin = 0.0;  // beyond the world's contact margin [m]
  bool is_static = false;
  LatestValue<Pose> pose_in;  // written by the object's mover, read by the collision step
  // collision thread
  Pose pose{};
  bool has_pose = false;
  std::int32_t proxy = DynamicAabbTree::kNull;  // broad-phase proxy once posed
  // the root sphere in the world at `pose`
  Vec3 centre_world() const { return transform_point(pose, to_vec(now->root())); }
  double radius() const { return static_cast<double>(now->root().radius); }
};

struct CollisionWorld::Watcher {
  WatcherId id = -1;
  Object* a = nullptr;  // null: the tool against every object
  Object* b = nullptr;
  // collision thread
  bool touching = false;
  std::uint64_t sequence = 0;
  std::int64_t frame_bytes = 0;  // heap bytes of the three frames (each changes only with its slot's holder)
  LatestValue<ContactFrame> frames;             // written by the collision step, read by take_contact()
  std::unique_ptr<VolumeQuery> coherent_query;  // with coherence_skin > 0: this pair's own query
};

CollisionWorld::CollisionWorld(CollisionWorldOptions options)
    : options_(std::move(options)),
      objects_by_id_(std::clamp(options_.max_objects, 1, 1 << kSlotBits)),
      watchers_by_id_(std::clamp(options_.max_objects, 1, 1 << kSlotBits)),
      changes_(static_cast<std::size_t>(std::max(options_.max_pending_changes, 1))),
      retired_(static_cast<std::size_t>(std::max(options_.max_pending_changes, 1))),
      broad_phase_(2 * std::clamp(options_.max_objects, 1, 1 << kSlotBits)),
      volume_query_(
          VolumeQueryOptions{.contact_margin = static_cast<float>(std::max(0.0, options_.contact_margin))}),
      loop_(FixedRateLoopOptions{.rate_hz = options_.rate_hz > 0.0 ? options_.rate_hz : 1000.0,
                                 .raise_priority = options_.raise_priority,
                                 .fifo_priority = options_.fifo_priority,
                                 .name = options_.thread_name}) {
  options_.max_objects = std::clamp(options_.max_objects, 1, 1 << kSlotBits);
  options_.max_pending_changes = std::max(options_.max_pending_changes, 1);
  const auto n = static_cast<std::size_t>(options_.max_objects);
  objects_.reserve(n);
  slot_objects_.assign(n, nullptr);
  watchers_.reserve(n);
  moving_.reserve(n);
  candidates_.reserve(n);
  retire_backlog_.reserve(static_cast<std::size_t>(options_.max_pending_changes));
}

CollisionWorld::~CollisionWorld() {
  stop();
  // the thread is gone: everything still registered is freed here, with the slot tables
  for (Watcher* w : watchers_) delete w;
  for (Object* o : objects_) delete o;
}

template <typename T>
CollisionWorld::SlotTable<T>::SlotTable(int capacity)
    : slots_(static_cast<std::uint32_t>(capacity), kGenerationMask, /*first_generation=*/0) {}

template <typename T>
std::int32_t CollisionWorld::SlotTable<T>::next_id() const {
  const std::optional<core::SlotId> id = slots_.next_id();
  return id ? make_id(static_cast<std::int32_t>(id->index), id->generation) : -1;
}

template <typename T>
void CollisionWorld::SlotTable<T>::occupy(T* item) {
  const std::optional<core::SlotId> id = slots_.occupy();
  slots_.item(id->index).store(item, std::memory_order_release);
}

template <typename T>
void CollisionWorld::SlotTable<T>::release(std::int32_t id) {
  slots_.item(static_cast<std::uint32_t>(slot_of(id))).store(nullptr, std::memory_order_release);
  slots_.release(slot_id(id));
}

template <typename T>
T* CollisionWorld::SlotTable<T>::find(std::int32_t id) const {
  if (id < 0 || !slots_.is_live(slot_id(id))) return nullptr;
  T* item = slots_.item(static_cast<std::uint32_t>(slot_of(id))).load(std::memory_order_acquire);
  // released meanwhile (the slot's generation moved on): not this id's item
  return slots_.is_live(slot_id(id)) ? item : nullptr;
}

CollisionWorld::Object* CollisionWorld::find_object(ObjectId id) const { return objects_by_id_.find(id); }

CollisionWorld::Watcher* CollisionWorld::find_watcher(WatcherId id) const { return watchers_by_id_.find(id); }

Status CollisionWorld::stale_object_error(const char* what, ObjectId id) const {
  if (id < 0 || slot_of(id) >= objects_by_id_.slots_used())
    return Error{fmt::format("CollisionWorld::{}: there is no object with id {}", what, id)};
  return Error{
      fmt::format("CollisionWorld::{}: object id {} is stale: that object was removed (slot {}, generation "
                  "{}; the slot is at "
                  "generation {} now)",
                  what, id, slot_of(id), generation_of(id), objects_by_id_.generation(slot_of(id)))};
}

Status CollisionWorld::submit(const Change& change) {
  free_retired();
  if (!running()) {
    // no collision thread: this thread holds its role and applies the change at once
    apply_pending();
    apply(change);
    free_retired();
    return Ok{};
  }
  if (!changes_.try_push(change))
    return Error{fmt::format(
        "CollisionWorld: more than {} changes wait for the collision thread; retry after its next step",
        options_.max_pending_changes)};
  return Ok{};
}

void CollisionWorld::apply_pending() {
  Change change{};
  while (changes_.try_pop(change)) apply(change);
  while (!retire_backlog_.empty() && retired_.try_push(retire_backlog_.back())) retire_backlog_.pop_back();
}

void CollisionWorld::free_retired() {
  Change change{};
  while (retired_.try_pop(change)) {
    delete change.object;
    delete change.watcher;
  }
}

// Collision thread (or the controlling thread while none runs): the vectors were reserved for
// max_objects entries, so these never allocate; retiring hands the item back to be freed.
void CollisionWorld::apply(const Change& change) {
  const auto retire = [this](Change c) {
    if (!retired_.try_push(c)) retire_backlog_.push_back(c);
  };
  switch (change.kind) {
    case Change::Kind::kAddObject: {
      Object* o = change.object;
      objects_.push_back(o);
      slot_objects_[static_cast<std::size_t>(slot_of(o->id))] = o;
      if (!o->is_static) moving_.push_back(o);
      if (o->has_pose) update_broad_phase(*o);
      break;
    }
    case Change::Kind::kRemoveObject: {
      Object* o = change.object;
      std::erase(objects_, o);
      std::erase(moving_, o);
      slot_objects_[static_cast<std::size_t>(slot_of(o->id))] = nullptr;
      if (o->proxy != DynamicAabbTree::kNull) broad_phase_.destroy(o->proxy);
      retire({.kind = change.kind, .object = o});
      break;
    }
    case Change::Kind::kAddWatcher:
      watchers_.push_back(change.watcher);
      break;
    case Change::Kind::kRemoveWatcher: {
      Watcher* w = change.watcher;
      std::erase(watchers_, w);
      frame_bytes_.fetch_sub(w->frame_bytes, std::memory_order_relaxed);
      retire({.kind = change.kind, .watcher = w});
      break;
    }
  }
  live_objects_.store(static_cast<std::int32_t>(objects_.size()), std::memory_order_relaxed);
  live_watchers_.store(static_cast<std::int32_t>(watchers_.size()), std::memory_order_relaxed);
}

Result<ObjectId> CollisionWorld::add_object(CollisionObjectDef def) {
  if (!def.tree || def.tree->empty())
    return Error{fmt::format("CollisionWorld::add_object: object '{}' has no sphere tree", def.name)};
  if (!(def.coverage > 0.0 && def.coverage <= 1.0))
    return Error{fmt::format("CollisionWorld::add_object: object '{}' has coverage {}; expected (0, 1]",
                             def.name, def.coverage)};
  const ObjectId id = objects_by_id_.next_id();
  if (id < 0)
    return Error{fmt::format(
        "CollisionWorld::add_object: object '{}' does not fit: the world holds at most {} objects", def.name,
        options_.max_objects)};
  if (!(def.extra_margin_m >= 0.0 && def.extra_margin_m < 1e3))
    return Error{fmt::format("CollisionWorld::add_object: object '{}' has extra margin {} m; expected [0, 1000)",
                             def.name, def.extra_margin_m)};
  if (def.deformed_trees != nullptr && def.is_static)
    return Error{fmt::format("CollisionWorld::add_object: object '{}' deforms: it cannot be static", def.name)};
  auto object = std::make_unique<Object>();
  object->id = id;
  object->tree = std::move(def.tree);
  object->now = object->tree.get();
  object->deformed_trees = def.deformed_trees;
  object->name = std::move(def.name);
  object->coverage = def.coverage;
  object->extra_margin = def.extra_margin_m;
  object->is_static = def.is_static;
  object->pose = def.world_from_object;
  object->has_pose = def.has_initial_pose;
  if (def.has_initial_pose) object->pose_in.write(def.world_from_object);
  Object* raw = object.get();
  if (auto sent = submit({.kind = Change::Kind::kAddObject, .object = raw}); !sent) return sent.error();
  object.release();  // the world owns it now: freed after the collision thread retired it
  objects_by_id_.occupy(raw);
  return id;
}

Status CollisionWorld::remove_object(ObjectId id) {
  Object* o = find_object(id);
  if (o == nullptr) return stale_object_error("remove_object", id);
  for (std::int32_t i = 0; i < watchers_by_id_.slots_used(); ++i) {
    const Watcher* w = watchers_by_id_.at_slot(i);
    if (w != nullptr && (w->a == o || w->b == o))
      return Error{fmt::format(
          "CollisionWorld::remove_object: object '{}' (id {}) is watched by watcher {}; remove the "
          "watcher first",
          o->name, id, w->id)};
  }
  if (auto sent = submit({.kind = Change::Kind::kRemoveObject, .object = o}); !sent) return sent;
  objects_by_id_.release(id);
  return Ok{};
}

Result<WatcherId> CollisionWorld::add_watcher(Object* a, Object* b) {
  const WatcherId id = watchers_by_id_.next_id();
  if (id < 0)
    return Error{fmt::format("CollisionWorld: the world holds at most {} watchers", options_.max_objects)};
  auto watcher = std::make_unique<Watcher>();
  watcher->id = id;
  watcher->a = a;
  watcher->b = b;
  if (options_.coherence_skin > 0.0 && a != nullptr)
    watcher->coherent_query = std::make_unique<VolumeQuery>(
        VolumeQueryOptions{.contact_margin = static_cast<float>(pair_margin(*a, *b)),
                           .coherence_skin = static_cast<float>(options_.coherence_skin)});
  Watcher* raw = watcher.get();
  if (auto sent = submit({.kind = Change::Kind::kAddWatcher, .watcher = raw}); !sent) return sent.error();
  watcher.release();
  watchers_by_id_.occupy(raw);
  return id;
}

Result<WatcherId> CollisionWorld::add_collision_watcher(ObjectId a, ObjectId b) {
  Object* oa = find_object(a);
  if (oa == nullptr) return stale_object_error("add_collision_watcher", a).error();
  Object* ob = find_object(b);
  if (ob == nullptr) return stale_object_error("add_collision_watcher", b).error();
  if (a == b)
    return Error{
        fmt::format("CollisionWorld::add_collision_watcher: object {} cannot be watched against itself", a)};
  for (std::int32_t i = 0; i < watchers_by_id_.slots_used(); ++i) {
    const Watcher* w = watchers_by_id_.at_slot(i);
    if (w != nullptr && ((w->a == oa && w->b == ob) || (w->a == ob && w->b == oa)))
      return Error{
          fmt::format("CollisionWorld::add_collision_watcher: pair ({}, {}) is watched already", a, b)};
  }
  return add_watcher(oa, ob);
}

Result<WatcherId> CollisionWorld::add_tool_watcher(ObjectId tool) {
  Object* o = find_object(tool);
  if (o == nullptr) return stale_object_error("add_tool_watcher", tool).error();
  for (std::int32_t i = 0; i < watchers_by_id_.slots_used(); ++i) {
    const Watcher* w = watchers_by_id_.at_slot(i);
    if (w != nullptr && w->a == nullptr && w->b == o)
      return Error{fmt::format(
          "CollisionWorld::add_tool_watcher: object {} is watched against everything already", tool)};
  }
  return add_watcher(nullptr, o);
}

Status CollisionWorld::remove_watcher(WatcherId id) {
  Watcher* w = find_watcher(id);
  if (w == nullptr) {
    if (id < 0 || slot_of(id) >= watchers_by_id_.slots_used())
      return Error{fmt::format("CollisionWorld::remove_watcher: there is no watcher with id {}", id)};
    return Error{
        fmt::format("CollisionWorld::remove_watcher: watcher id {} is stale: that watcher was removed", id)};
  }
  if (auto sent = submit({.kind = Change::Kind::kRemoveWatcher, .watcher = w}); !sent) return sent;
  watchers_by_id_.release(id);
  return Ok{};
}

bool CollisionWorld::set_pose(ObjectId id, const Pose& world_from_object) {
  Object* o = find_object(id);
  if (o == nullptr || o->is_static) {
    stale_poses_.increment();
    return false;
  }
  o->pose_in.write(world_from_object);
  return true;
}

const ContactFrame* CollisionWorld::take_contact(WatcherId watcher) {
  Watcher* w = find_watcher(watcher);
  if (w == nullptr || !w->frames.update()) return nullptr;
  return &w->frames.read_buffer();
}

bool CollisionWorld::read_contact(WatcherId watcher, ContactFrame& out) {
  const ContactFrame* frame = take_contact(watcher);
  if (frame == nullptr) return false;
  copy_contact_frame(*frame, out);
  return true;
}

Status CollisionWorld::start() {
  if (running()) return Error{"CollisionWorld::start: the collision thread runs already"};
  if (watchers_by_id_.count() == 0)
    return Error{"CollisionWorld::start: nothing is watched (add a watcher first)", ErrorKind::kInvalid};
  apply_pending();
  free_retired();
  step_time_.reset();
  query_time_.reset();
  steps_.store(0);
  queries_.reset();
  contact_frames_.reset();
  truncated_frames_.reset();
  coherent_queries_.reset();
  broad_phase_candidates_.reset();
  max_pairs_.store(0);
  stop_requested_.store(false);
  if (options_.rate_hz > 0.0) {
    // frames are stamped on the steady clock [s since its epoch], the clock the haptic thread uses
    return loop_.start([this](const TickInfo& tick) {
      run_step(std::chrono::duration<double>(tick.start_time.time_since_epoch()).count());
    });
  }
  free_running_.store(true);
  free_thread_ = std::thread([this] {
    while (!stop_requested_.load(std::memory_order_relaxed)) run_step(now_seconds());
    free_running_.store(false);
  });
  return Ok{};
}

void CollisionWorld::stop() {
  loop_.stop();
  stop_requested_.store(true);
  if (free_thread_.joinable()) free_thread_.join();
  // the collision thread is joined: this thread takes its role for what it left
  apply_pending();
  free_retired();
}

bool CollisionWorld::running() const { return loop_.running() || free_running_.load(); }

void CollisionWorld::step(double time_s) { run_step(time_s); }

double CollisionWorld::pair_margin(const Object& a, const Object& b) const {
  return std::max(0.0, options_.contact_margin) + a.extra_margin + b.extra_margin;
}

void CollisionWorld::update_broad_phase(Object& o) {
  const Aabb box = aabb::of_sphere(o.centre_world(), o.radius() + o.extra_margin);
  const double margin = o.is_static ? 0.0 : std::max(0.0, options_.broad_phase_margin);
  if (o.proxy == DynamicAabbTree::kNull)
    o.proxy = broad_phase_.create(box, margin, slot_of(o.id));
  else
    broad_phase_.move(o.proxy, box, margin);
}

void CollisionWorld::query_pair(Watcher& watcher, ContactFrame& frame) {
  const Object& a = *watcher.a;
  const Object& b = *watcher.b;
  const double root_gap = norm(b.centre_world() - a.centre_world()) - a.radius() - b.radius();
  const double margin = pair_margin(a, b);
  if (root_gap < margin) {
    const auto query_start = std::chrono::steady_clock::now();
    if (!watcher.coherent_query) volume_query_.set_contact_margin(static_cast<float>(margin));
    VolumeQuery& query = watcher.coherent_query ? *watcher.coherent_query : volume_query_;
    query.run(*a.now, *b.now, a.pose, b.pose, frame);
    if (query.result().reused_candidates) coherent_queries_.increment();
    query_time_.record(elapsed_ns(query_start));
    queries_.increment();
  } else {
    frame.total_volume = 0.0;
    frame.pair_count = 0;
    frame.section_count = 0;
    frame.truncated = false;
    frame.restoring_direction_world = Vec3{};
    frame.volume_centroid_world = Vec3{};
    frame.volume_gradient_world = Vec3{};
    frame.query_seconds = 0.0;
    frame.world_from_a = a.pose;
    frame.world_from_b = b.pose;
  }
  if (!(frame.total_volume > 0.0) && options_.compute_distance) {
    // the root gap is only a lower bound; the distance query gives the packing's separation
    frame.distance = distance_query_.run(*a.now, *b.now, inverse(a.pose) * b.pose).distance;
  } else if (frame.total_volume > 0.0) {
    frame.distance = 0.0;
  }
  frame.object_a = a.id;
  for (ContactSection& s : frame.sections()) {
    s.object_a = a.id;
    s.object_b = b.id;
    s.coverage_product = a.coverage * b.coverage;
  }
}

void CollisionWorld::query_tool(Watcher& watcher, ContactFrame& frame) {
  const Object& tool = *watcher.b;
  const auto frame_start = std::chrono::steady_clock::now();
  frame.pair_count = 0;
  frame.section_count = 0;
  frame.truncated = false;
  frame.object_a = ContactFrame::kEveryObject;
  frame.world_from_a = Pose{};
  frame.world_from_b = tool.pose;
  const Vec3 tool_centre = tool.centre_world();
  const double margin = std::max(0.0, options_.contact_margin);
  candidates_.clear();
  broad_phase_.query(aabb::of_sphere(tool_centre, tool.radius() + margin), [&](std::int32_t slot) {
    Object* o = slot_objects_[static_cast<std::size_t>(slot)];
    if (o != &tool) candidates_.push_back(o);
    return true;
  });
  broad_phase_candidates_.add(candidates_.size());
  double volume = 0.0;
  Vec3 weighted_normal{}, weighted_centroid{}, gradient{};
  for (Object* o : candidates_) {
    if (!o->has_pose) continue;
    const double root_gap = norm(tool_centre - o->centre_world()) - o->radius() - tool.radius();
    const double object_margin = pair_margin(*o, tool);
    if (!(root_gap < object_margin)) continue;
    const auto query_start = std::chrono::steady_clock::now();
    volume_query_.set_contact_margin(static_cast<float>(object_margin));
    const ContactSection& s = volume_query_.append_section(*o->now, *tool.now, o->pose, tool.pose, frame);
    query_time_.record(elapsed_ns(query_start));
    queries_.increment();
    const VolumeQueryResult& r = volume_query_.result();
    if (s.pair_count == 0) {
      --frame.section_count;  // no pairs: nothing to hold
      continue;
    }
    ContactSection& kept = frame.sections().back();
    kept.object_a = o->id;
    kept.object_b = tool.id;
    kept.coverage_product = o->coverage * tool.coverage;
    frame.truncated = frame.truncated || kept.truncated;
    volume += r.total_volume;
    weighted_normal += transform_vector(o->pose, r.weighted_normal_sum);
    weighted_centroid += r.total_volume * transform_point(o->pose, r.volume_centroid);
    gradient += kept.volume_gradient_world;
  }
  frame.total_volume = volume;
  const double n = norm(weighted_normal);
  frame.restoring_direction_world = n > 0.0 ? weighted_normal / n : Vec3{};
  frame.volume_centroid_world = volume > 0.0 ? weighted_centroid / volume : Vec3{};
  frame.volume_gradient_world = gradient;
  // a tool against everything has no one partner to measure the separation to
  frame.distance = volume > 0.0 ? 0.0 : std::numeric_limits<double>::infinity();
  frame.query_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - frame_start).count();
}

void CollisionWorld::run_step(double time_s) {
  const auto step_start = std::chrono::steady_clock::now();
  apply_pending();
  for (Object* object : moving_) {
    bool moved = false;
    if (object->pose_in.update()) {
      object->pose = object->pose_in.read_buffer();
      object->has_pose = true;
      moved = true;
    }
    // a new deformed tree is always in another slot than the one read before (the triple buffer
    // never hands back the slot it takes), so a coherent query, which keeps candidates only for
    // the tree at their address, traverses it afresh (WorldFixture.CoherentWatchersFollowADeformingTree)
    if (object->deformed_trees != nullptr && object->deformed_trees->update()) {
      object->now = &object->deformed_trees->read_buffer();
      moved = true;
    }
    if (moved && object->has_pose) update_broad_phase(*object);
  }

  std::int64_t pairs_this_step = 0;
  for (Watcher* watcher_ptr : watchers_) {
    Watcher& watcher = *watcher_ptr;
    if (!watcher.b->has_pose || (watcher.a != nullptr && !watcher.a->has_pose))
      continue;  // nothing to report before the mover's first pose
    ContactFrame& frame = watcher.frames.write_buffer();
    const auto bytes_before = static_cast<std::int64_t>(frame.memory_bytes());
    if (watcher.a != nullptr)
      query_pair(watcher, frame);
    else
      query_tool(watcher, frame);
    frame.trim_pairs(frame.pair_count);  // a deep contact that ended gives its memory back
    const auto bytes_delta = static_cast<std::int64_t>(frame.memory_bytes()) - bytes_before;
    watcher.frame_bytes += bytes_delta;
    frame_bytes_.fetch_add(bytes_delta, std::memory_order_relaxed);
    frame.sequence = ++watcher.sequence;
    frame.time_s = time_s;
    frame.object_b = watcher.b->id;

    const bool touching = frame.pair_count > 0;
    pairs_this_step += frame.pair_count;
    if (frame.total_volume > 0.0) contact_frames_.increment();
    if (frame.truncated) truncated_frames_.increment();
    if (touching || watcher.touching) on_collision_.broadcast(frame.object_a, frame.object_b, frame);
    watcher.touching = touching;
    watcher.frames.publish();
  }
  on_step_.broadcast(time_s);

  last_pairs_.store(pairs_this_step, std::memory_order_relaxed);
  if (pairs_this_step > max_pairs_.load(std::memory_order_relaxed))
    max_pairs_.store(pairs_this_step, std::memory_order_relaxed);
  step_time_.record(elapsed_ns(step_start));
  const double now = now_seconds();
  if (steps_.load(std::memory_order_relaxed) == 0) first_step_s_.store(now, std::memory_order_relaxed);
  last_step_s_.store(now, std::memory_order_relaxed);
  steps_.fetch_add(1, std::memory_order_release);
}

CollisionWorldStats CollisionWorld::stats() const {
  CollisionWorldStats s;
  s.steps = steps_.load(std::memory_order_acquire);
  const double span = last_step_s_.load(std::memory_order_relaxed) - first_step_s_.load(std::memory_order_relaxed);
  s.rate_hz = (s.steps > 1 && span > 0.0) ? static_cast<double>(s.steps - 1) / span : 0.0;
  s.step_time = step_time_.summary();
  s.query_time = query_time_.summary();
  s.queries = queries_.load();
  s.contact_frames = contact_frames_.load();
  s.truncated_frames = truncated_frames_.load();
  s.coherent_queries = coherent_queries_.load();
  s.last_pairs = last_pairs_.load(std::memory_order_relaxed);
  s.max_pairs = max_pairs_.load(std::memory_order_relaxed);
  if (options_.rate_hz > 0.0) s.missed_deadlines = loop_.stats().missed_deadlines;
  s.broad_phase_candidates = broad_phase_candidates_.load();
  s.stale_poses = stale_poses_.load();
  s.objects = live_objects_.load(std::memory_order_relaxed);
  s.watchers = live_watchers_.load(std::memory_order_relaxed);
  s.frame_bytes = frame_bytes_.load(std::memory_order_relaxed);
  s.running = running();
  return s;
}

}  // namespace uh::collette
