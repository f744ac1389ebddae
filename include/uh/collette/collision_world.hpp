#pragma once
/// \file
/// CollisionWorld: the paper's ColletteVolume. Objects (an Inner Sphere Tree and a pose) are
/// registered, pairs of them are watched (AddCollisionWatcher), and a collision thread queries the
/// watched pairs at a fixed rate (or free-running), broadcasts **OnCollision** and publishes each
/// watcher's newest ContactFrame through a lock-free latest-value handoff.
///
/// Thread rules:
///  - setup (add_object, add_collision_watcher, on_collision().add_delegate) happens on the
///    controlling thread before start(); start()/stop() on the controlling thread;
///  - set_pose(id, ...) for one object is called by exactly one thread (the one that moves it, e.g.
///    the haptic thread for the tool, the game thread for scene objects); real-time safe;
///  - OnCollision delegates run on the collision thread (or the thread calling step()); they get
///    the frame by reference, valid only during the call; copy what you keep with
///    uh::copy_contact_frame into your own handoff;
///  - read_contact(watcher, ...) is called by exactly one reader thread per watcher; real-time safe;
///  - stats() from any thread, lock-free.
///
/// Time: the collision thread stamps each frame's time_s with the steady clock in seconds since
/// its epoch (the clock HapticManager ticks on), so a consumer can tell the age of a frame;
/// step(time_s) stamps the time it is given.
///
/// Broad phase: the bounding spheres of the two roots at their current poses; the tree traversal
/// runs only when they overlap. When apart, `distance` is filled (upper bound on the separation)
/// if the options ask for it.

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "uh/collette/distance_query.hpp"
#include "uh/collette/sphere_tree.hpp"
#include "uh/collette/volume_query.hpp"
#include "uh/core/contact.hpp"
#include "uh/core/delegator.hpp"
#include "uh/core/event_counter.hpp"
#include "uh/core/fixed_rate_loop.hpp"
#include "uh/core/latency_histogram.hpp"
#include "uh/core/latest_value.hpp"
#include "uh/core/math.hpp"
#include "uh/core/result.hpp"

namespace uh::collette {

using ObjectId = std::int32_t;
using WatcherId = std::int32_t;

/// Options of a CollisionWorld (aggregate; designated initialisers).
struct CollisionWorldOptions {
  double rate_hz = 1000.0;        ///< collision thread rate [Hz]; 0 = free-running (as fast as it can)
  bool raise_priority = false;    ///< ask for SCHED_FIFO for the collision thread (reported, not fatal)
  int fifo_priority = 70;         ///< SCHED_FIFO priority when raised: below the haptic thread's 80
  bool compute_distance = true;   ///< fill ContactFrame::distance when a watched pair is apart
  /// Leaf pairs closer than this [length] are delivered with volume 0 before they overlap (see
  /// VolumeQueryOptions::contact_margin), so multi-rate force rendering starts contacts smoothly.
  double contact_margin = 0.0;
  /// Frame-to-frame coherence of each watched pair's volume query (see
  /// VolumeQueryOptions::coherence_skin) [length]; 0 = traverse every step. Each watcher then owns
  /// its query (about 1.2 MB of pair buffer), since the kept candidates belong to one pair.
  double coherence_skin = 0.0;
  std::string thread_name = "uh-collision";
};

/// An object to register: its tree (shared, immutable) and initial world pose.
struct CollisionObjectDef {
  std::shared_ptr<const SphereTree> tree;  ///< non-empty, validated tree
  Pose world_from_object{};                ///< initial pose of the object's mesh frame in the world
  /// False for an object whose pose only its mover knows (e.g. a tool bound to a device): its
  /// watched pairs are skipped until the first set_pose(), instead of colliding at a made-up pose.
  bool has_initial_pose = true;
  std::string name;                        ///< for messages
};

/// Statistics of the collision thread since start(). Plain data.
struct CollisionWorldStats {
  std::uint64_t steps = 0;              ///< collision steps run (all watchers queried once)
  double rate_hz = 0.0;                 ///< achieved step rate [Hz]
  LatencySummary step_time;             ///< duration of a step (all watchers) [ns]
  LatencySummary query_time;            ///< duration of one watcher's query when its roots overlap [ns]
  std::uint64_t queries = 0;            ///< tree queries run (broad phase passed)
  std::uint64_t contact_frames = 0;     ///< frames with at least one overlapping pair
  std::uint64_t truncated_frames = 0;   ///< frames with more pairs than ContactFrame::kMaxPairs
  std::uint64_t coherent_queries = 0;   ///< queries that reused their kept candidates (coherence_skin > 0)
  std::int64_t last_pairs = 0;          ///< pairs of the last frame, summed over watchers
  std::int64_t max_pairs = 0;           ///< largest pair count of one frame
  std::uint64_t missed_deadlines = 0;   ///< fixed-rate mode: steps that started a period late
  bool running = false;
};

/// The collision world. Not copyable or movable (delegates and threads refer to it).
class CollisionWorld {
 public:
  /// Signature of OnCollision: ids of A and B and the frame (world frame, valid during the call).
  using OnCollision = Delegator<ObjectId, ObjectId, const ContactFrame&>;

  explicit CollisionWorld(CollisionWorldOptions options = {});
  /// Stops the collision thread if it runs.
  ~CollisionWorld();
  CollisionWorld(const CollisionWorld&) = delete;
  CollisionWorld& operator=(const CollisionWorld&) = delete;

  /// Registers an object; returns its id (0, 1, 2, ...). Fails on an empty tree or while running.
  /// Controlling thread, before start().
  Result<ObjectId> add_object(CollisionObjectDef def);

  /// Watches the pair (a, b): the collision thread queries it every step. B is pushed out of A by
  /// the frame's restoring direction. Fails on unknown ids, a == b, a pair watched already, or while
  /// running. Controlling thread, before start(). (The paper's AddCollisionWatcher.)
  Result<WatcherId> add_collision_watcher(ObjectId a, ObjectId b);

  /// Binds OnCollision: called on the collision thread for every step in which the watched pair
  /// has pairs (overlapping, or within the contact margin), and once more with an empty frame
  /// (pair_count 0) when that ends.
  DelegateSink<ObjectId, ObjectId, const ContactFrame&> on_collision() { return DelegateSink(on_collision_); }

  /// Sets the world pose of an object. One writer thread per object; real-time safe (lock-free).
  void set_pose(ObjectId id, const Pose& world_from_object);

  /// Copies the newest frame of `watcher` into `out` if a newer one than the last call arrived;
  /// returns whether it did. One reader thread per watcher; real-time safe.
  bool read_contact(WatcherId watcher, ContactFrame& out);

  /// Starts the collision thread (fixed rate, or free-running when rate_hz is 0).
  /// Controlling thread. Fails when nothing is watched or already running.
  Status start();
  /// Stops and joins the collision thread. Idempotent. Controlling thread.
  void stop();
  bool running() const;

  /// Runs one collision step on the calling thread (for stepped sessions and tests; never while
  /// the thread runs). `time_s` is stamped into the frames.
  void step(double time_s);

  /// Lock-free statistics; any thread.
  CollisionWorldStats stats() const;

  int object_count() const { return static_cast<int>(objects_.size()); }
  int watcher_count() const { return static_cast<int>(watchers_.size()); }
  const SphereTree& tree(ObjectId id) const { return *objects_[static_cast<std::size_t>(id)]->tree; }

 private:
  struct Object {
    std::shared_ptr<const SphereTree> tree;
    std::string name;
    LatestValue<Pose> pose_in;   // written by the object's mover, read by the collision step
    Pose pose{};                 // collision thread's copy
    bool has_pose = false;       // collision thread: a pose was given (initially or by set_pose)
  };
  struct Watcher {
    ObjectId a = -1;
    ObjectId b = -1;
    bool touching = false;
    std::uint64_t sequence = 0;
    LatestValue<ContactFrame> frames;  // written by the collision step, read by read_contact()
    std::unique_ptr<VolumeQuery> coherent_query;  // with coherence_skin > 0: this pair's own query
  };

  void run_step(double time_s);

  CollisionWorldOptions options_;
  std::vector<std::unique_ptr<Object>> objects_;
  std::vector<std::unique_ptr<Watcher>> watchers_;
  OnCollision on_collision_;
  VolumeQuery volume_query_;
  DistanceQuery distance_query_;
  FixedRateLoop loop_;
  std::thread free_thread_;
  std::atomic<bool> free_running_{false};
  std::atomic<bool> stop_requested_{false};
  LatencyHistogram step_time_;
  LatencyHistogram query_time_;
  std::atomic<std::uint64_t> steps_{0};
  std::atomic<double> first_step_s_{0.0};
  std::atomic<double> last_step_s_{0.0};
  EventCounter queries_;
  EventCounter contact_frames_;
  EventCounter truncated_frames_;
  EventCounter coherent_queries_;
  std::atomic<std::int64_t> last_pairs_{0};
  std::atomic<std::int64_t> max_pairs_{0};
};

}  // namespace uh::collette
