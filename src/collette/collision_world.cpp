#include "uh/collette/collision_world.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

#include <fmt/format.h>

namespace uh::collette {
namespace {

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::uint64_t elapsed_ns(std::chrono::steady_clock::time_point since) {
  return static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - since).count());
}

// Bounding sphere of the whole object in the world frame.
Vec3 root_center_world(const SphereTree& tree, const Pose& world_from_object) {
  const SphereTreeNode& r = tree.root();
  return transform_point(world_from_object, Vec3{static_cast<double>(r.x), static_cast<double>(r.y), static_cast<double>(r.z)});
}

}  // namespace

CollisionWorld::CollisionWorld(CollisionWorldOptions options)
    : options_(std::move(options)),
      volume_query_(VolumeQueryOptions{.contact_margin = static_cast<float>(std::max(0.0, options_.contact_margin))}),
      loop_(FixedRateLoopOptions{.rate_hz = options_.rate_hz > 0.0 ? options_.rate_hz : 1000.0,
                                 .raise_priority = options_.raise_priority,
                                 .fifo_priority = options_.fifo_priority,
                                 .name = options_.thread_name}) {}

CollisionWorld::~CollisionWorld() { stop(); }

Result<ObjectId> CollisionWorld::add_object(CollisionObjectDef def) {
  if (running()) return Error{"CollisionWorld::add_object: cannot add objects while the collision thread runs"};
  if (!def.tree || def.tree->empty())
    return Error{fmt::format("CollisionWorld::add_object: object '{}' has no sphere tree", def.name)};
  auto object = std::make_unique<Object>();
  object->tree = std::move(def.tree);
  object->name = std::move(def.name);
  object->pose = def.world_from_object;
  object->has_pose = def.has_initial_pose;
  if (def.has_initial_pose) object->pose_in.write(def.world_from_object);
  objects_.push_back(std::move(object));
  return static_cast<ObjectId>(objects_.size() - 1);
}

Result<WatcherId> CollisionWorld::add_collision_watcher(ObjectId a, ObjectId b) {
  if (running()) return Error{"CollisionWorld::add_collision_watcher: cannot watch pairs while the collision thread runs"};
  const auto n = static_cast<ObjectId>(objects_.size());
  if (a < 0 || a >= n || b < 0 || b >= n)
    return Error{fmt::format("CollisionWorld::add_collision_watcher: unknown object id ({}, {}); {} objects registered", a, b, n)};
  if (a == b) return Error{fmt::format("CollisionWorld::add_collision_watcher: object {} cannot be watched against itself", a)};
  for (const auto& w : watchers_)
    if ((w->a == a && w->b == b) || (w->a == b && w->b == a))
      return Error{fmt::format("CollisionWorld::add_collision_watcher: pair ({}, {}) is watched already", a, b)};
  auto watcher = std::make_unique<Watcher>();
  watcher->a = a;
  watcher->b = b;
  if (options_.coherence_skin > 0.0)
    watcher->coherent_query = std::make_unique<VolumeQuery>(
        VolumeQueryOptions{.contact_margin = static_cast<float>(std::max(0.0, options_.contact_margin)),
                           .coherence_skin = static_cast<float>(options_.coherence_skin)});
  watchers_.push_back(std::move(watcher));
  return static_cast<WatcherId>(watchers_.size() - 1);
}

void CollisionWorld::set_pose(ObjectId id, const Pose& world_from_object) {
  if (id < 0 || id >= static_cast<ObjectId>(objects_.size())) return;
  objects_[static_cast<std::size_t>(id)]->pose_in.write(world_from_object);
}

bool CollisionWorld::read_contact(WatcherId watcher, ContactFrame& out) {
  if (watcher < 0 || watcher >= static_cast<WatcherId>(watchers_.size())) return false;
  auto& frames = watchers_[static_cast<std::size_t>(watcher)]->frames;
  if (!frames.update()) return false;
  copy_contact_frame(frames.read_buffer(), out);
  return true;
}

Status CollisionWorld::start() {
  if (running()) return Error{"CollisionWorld::start: the collision thread runs already"};
  if (watchers_.empty()) return Error{"CollisionWorld::start: no pair is watched (call add_collision_watcher first)"};
  step_time_.reset();
  query_time_.reset();
  steps_.store(0);
  queries_.reset();
  contact_frames_.reset();
  truncated_frames_.reset();
  coherent_queries_.reset();
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
}

bool CollisionWorld::running() const { return loop_.running() || free_running_.load(); }

void CollisionWorld::step(double time_s) { run_step(time_s); }

void CollisionWorld::run_step(double time_s) {
  const auto step_start = std::chrono::steady_clock::now();
  for (auto& object : objects_) {
    if (object->pose_in.update()) {
      object->pose = object->pose_in.read_buffer();
      object->has_pose = true;
    }
  }

  std::int64_t pairs_this_step = 0;
  for (auto& watcher : watchers_) {
    const Object& a = *objects_[static_cast<std::size_t>(watcher->a)];
    const Object& b = *objects_[static_cast<std::size_t>(watcher->b)];
    if (!a.has_pose || !b.has_pose) continue;  // nothing to report before the mover's first pose
    ContactFrame& frame = watcher->frames.write_buffer();

    const double root_gap = norm(root_center_world(*b.tree, b.pose) - root_center_world(*a.tree, a.pose)) -
                            static_cast<double>(a.tree->root().radius) - static_cast<double>(b.tree->root().radius);
    if (root_gap < options_.contact_margin) {
      const auto query_start = std::chrono::steady_clock::now();
      VolumeQuery& query = watcher->coherent_query ? *watcher->coherent_query : volume_query_;
      query.run(*a.tree, *b.tree, a.pose, b.pose, frame);
      if (query.result().reused_candidates) coherent_queries_.increment();
      query_time_.record(elapsed_ns(query_start));
      queries_.increment();
    } else {
      frame.total_volume = 0.0;
      frame.pair_count = 0;
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
      frame.distance = distance_query_.run(*a.tree, *b.tree, inverse(a.pose) * b.pose).distance;
    } else if (frame.total_volume > 0.0) {
      frame.distance = 0.0;
    }
    frame.sequence = ++watcher->sequence;
    frame.time_s = time_s;
    frame.object_a = watcher->a;
    frame.object_b = watcher->b;

    const bool touching = frame.pair_count > 0;
    pairs_this_step += frame.pair_count;
    if (frame.total_volume > 0.0) contact_frames_.increment();
    if (frame.truncated) truncated_frames_.increment();
    if (touching || watcher->touching) on_collision_.broadcast(watcher->a, watcher->b, frame);
    watcher->touching = touching;
    watcher->frames.publish();
  }

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
  s.running = running();
  return s;
}

}  // namespace uh::collette
