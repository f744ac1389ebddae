#pragma once
/// \file
/// CollisionWorld: the paper's ColletteVolume. Objects (an Inner Sphere Tree and a pose) are
/// registered, pairs of them, or a tool against every object, are watched, and a collision thread
/// queries the watched pairs at a fixed rate (or free-running), broadcasts **OnCollision** and
/// publishes each watcher's newest ContactFrame through a lock-free latest-value handoff.
///
/// Objects and watchers come and go while the thread runs. Their ids carry a generation: a slot
/// freed by a removal is reused with the next generation, so an id kept after its object was
/// removed is refused with a message saying so (never mistaken for the slot's new object).
///
/// Thread rules:
///  - add_object, remove_object, add_collision_watcher, add_tool_watcher, remove_watcher,
///    start(), stop() on one controlling thread, before or while the collision thread runs;
///    changes made while it runs take effect at the start of its next step (they travel through an
///    SpscQueue; what the thread retires comes back through another and is freed here);
///  - set_pose(id, ...) for one object is called by exactly one thread (the one that moves it, e.g.
///    the haptic thread for the tool, the game thread for scene objects); real-time safe. Its
///    mover stops calling it before the object is removed;
///  - OnCollision delegates run on the collision thread (or the thread calling step()); they get
///    the frame by reference, valid only during the call; copy what you keep with
///    uh::copy_contact_frame into your own handoff. Bind them before start();
///  - take_contact / read_contact(watcher) are called by exactly one reader thread per watcher;
///    real-time safe (take_contact). A watcher is removed only after its reader stopped reading it;
///  - stats() from any thread, lock-free.
///
/// Frames: each watcher owns a LatestValue<ContactFrame> (three frames). The collision thread
/// fills the write slot in place, growing its pair storage when a step finds more pairs than it
/// ever held and trimming it when far fewer overlap (outside the query; so memory follows the
/// overlap, about 3 x 72 bytes per pair), and publishes it; the reader takes the newest slot and
/// works on the pairs where they lie (take_contact): a frame crosses threads once, never copied.
///
/// Time: the collision thread stamps each frame's time_s with the steady clock in seconds since
/// its epoch (the clock HapticManager ticks on), so a consumer can tell the age of a frame;
/// step(time_s) stamps the time it is given.
///
/// Broad phase: every posed object has a box in a dynamic bounding-volume tree (DynamicAabbTree,
/// after Box2D's b2DynamicTree): the box of its root sphere, grown by a margin when it moves. A
/// tool watched against everything queries that tree with its own box, then each candidate's root
/// spheres, and runs the tree traversal only for those whose roots overlap (or are nearer than the
/// contact margin). A watched pair checks its two root spheres. When apart, `distance` is filled
/// for a watched pair (upper bound on the separation) if the options ask for it.

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "uh/collette/distance_query.hpp"
#include "uh/collette/dynamic_aabb_tree.hpp"
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
#include "uh/core/slot_table.hpp"
#include "uh/core/spsc_queue.hpp"

namespace uh::collette {

/// An object's id: its slot in the low 16 bits, the slot's generation above (both >= 0). The
/// first objects of a world get 0, 1, 2, ...
using ObjectId = std::int32_t;
/// A watcher's id, built the same way.
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
  /// Most objects (and most watchers) at a time; their slot tables are allocated once, so that
  /// movers and readers find them without a lock. At most 65,536.
  int max_objects = 1024;
  /// Most changes (adds and removes) the controlling thread may make between two collision steps.
  int max_pending_changes = 1024;
  /// A moving object's broad-phase box is its root sphere's box grown by this much [length] (plus
  /// the contact margin), so that it is re-inserted only when it left that box.
  double broad_phase_margin = 0.005;
};

/// An object to register: its tree (shared, immutable) and initial world pose.
struct CollisionObjectDef {
  std::shared_ptr<const SphereTree> tree;  ///< non-empty, validated tree
  Pose world_from_object{};                ///< initial pose of the object's mesh frame in the world
  /// False for an object whose pose only its mover knows (e.g. a tool bound to a device): its
  /// watched pairs are skipped until the first set_pose(), instead of colliding at a made-up pose.
  bool has_initial_pose = true;
  /// True for an object that never moves: set_pose() on it is refused, its broad-phase box is tight.
  bool is_static = false;
  /// The packing's coverage (sphere volume / mesh volume, (0, 1]); frames carry c_A c_B per section.
  double coverage = 1.0;
  std::string name;                        ///< for messages
  /// A deforming object's trees (a soft body's: uh::controllers::SoftSimulation refits and
  /// publishes them): each step takes the newest one, as it takes a pose, and queries it instead
  /// of `tree` (its rest shape, the same topology). Null for a rigid object. Owned by the caller,
  /// alive while the object is registered; the collision thread is its only reader. Not static.
  LatestValue<SphereTree>* deformed_trees = nullptr;
  /// Pairs with this object are reported this much farther than the world's contact_margin [m],
  /// >= 0: a tool resting on the object's mesh surface through a proxy hears of its spheres, which
  /// lie up to the packing's surface gap below the mesh, in time to keep off the mesh.
  double extra_margin_m = 0.0;
};

/// Statistics of the collision thread since start(). Plain data.
struct CollisionWorldStats {
  std::uint64_t steps = 0;              ///< collision steps run (all watchers queried once)
  double rate_hz = 0.0;                 ///< achieved step rate [Hz]
  LatencySummary step_time;             ///< duration of a step (all watchers) [ns]
  LatencySummary query_time;            ///< duration of one watcher's query when its roots overlap [ns]
  std::uint64_t queries = 0;            ///< tree queries run (broad phase passed)
  std::uint64_t contact_frames = 0;     ///< frames with at least one overlapping pair
  std::uint64_t truncated_frames = 0;   ///< frames whose query found more pairs than it could store
  std::uint64_t coherent_queries = 0;   ///< queries that reused their kept candidates (coherence_skin > 0)
  std::int64_t last_pairs = 0;          ///< pairs of the last frame, summed over watchers
  std::int64_t max_pairs = 0;           ///< largest pair count of one frame
  std::uint64_t missed_deadlines = 0;   ///< fixed-rate mode: steps that started a period late
  std::uint64_t broad_phase_candidates = 0;  ///< objects a tool watcher's broad-phase query returned
  std::uint64_t stale_poses = 0;  ///< set_pose() calls with a removed, unknown or static id (ignored)
  std::int32_t objects = 0;       ///< objects the collision thread knows at its last step
  std::int32_t watchers = 0;      ///< watchers the collision thread knows at its last step
  std::int64_t frame_bytes = 0;   ///< heap bytes of all watchers' frames (pairs and sections)
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

  /// Registers an object; returns its id. Fails on an empty tree, a full slot table or too many
  /// pending changes. Controlling thread; while running, the object takes part from the next step.
  Result<ObjectId> add_object(CollisionObjectDef def);
  /// Unregisters an object; its id (and any copy of it) is stale from now on. Fails on a stale or
  /// unknown id, and while a watcher names it (remove the watcher first). Controlling thread.
  Status remove_object(ObjectId id);

  /// Watches the pair (a, b): the collision thread queries it every step. B is pushed out of A by
  /// the frame's restoring direction. Fails on unknown or stale ids, a == b, a pair watched
  /// already. Controlling thread. (The paper's AddCollisionWatcher.)
  Result<WatcherId> add_collision_watcher(ObjectId a, ObjectId b);
  /// Watches `tool` against every other object, present and future: each frame has a section per
  /// object the tool overlaps (object_a = ContactFrame::kEveryObject in the header, the tool B).
  /// The broad phase picks the objects to query. Controlling thread.
  Result<WatcherId> add_tool_watcher(ObjectId tool);
  /// Stops watching; the id is stale from now on. Its reader must have stopped reading it.
  /// Controlling thread.
  Status remove_watcher(WatcherId watcher);

  /// Binds OnCollision: called on the collision thread for every step in which the watcher has
  /// pairs (overlapping, or within the contact margin), and once more with an empty frame
  /// (pair_count 0) when that ends.
  DelegateSink<ObjectId, ObjectId, const ContactFrame&> on_collision() { return DelegateSink(on_collision_); }
  /// Binds OnStep: called on the collision thread (or the thread calling step()) at the end of
  /// every step, after its OnCollision calls, with the step's time [s]. A mover that decides an
  /// object's next pose from this step's contacts (a tool's proxy) binds here and calls set_pose()
  /// from it: the next step queries that pose. Bind before start().
  DelegateSink<double> on_step() { return DelegateSink(on_step_); }

  /// Sets the world pose of an object. One writer thread per object; real-time safe (lock-free).
  /// Returns false (and counts it in stats().stale_poses) for a stale, unknown or static id.
  bool set_pose(ObjectId id, const Pose& world_from_object);

  /// The newest frame of `watcher` if one newer than the last call arrived, else nullptr. The
  /// frame stays valid and unchanged until the next call that returns a frame for this watcher
  /// (the reader owns its slot until then). One reader thread per watcher; real-time safe.
  const ContactFrame* take_contact(WatcherId watcher);
  /// Copies the newest frame of `watcher` into `out` if a newer one than the last call arrived;
  /// returns whether it did (take_contact plus a copy: for readers that keep frames). Allocates
  /// when `out` has less room than the frame.
  bool read_contact(WatcherId watcher, ContactFrame& out);

  /// Starts the collision thread (fixed rate, or free-running when rate_hz is 0).
  /// Controlling thread. Fails when nothing is watched or already running.
  Status start();
  /// Stops and joins the collision thread, then applies the changes it had not taken. Idempotent.
  /// Controlling thread.
  void stop();
  bool running() const;

  /// Runs one collision step on the calling thread (for stepped sessions and tests; never while
  /// the thread runs). `time_s` is stamped into the frames.
  void step(double time_s);

  /// Lock-free statistics; any thread.
  CollisionWorldStats stats() const;

  /// Registered objects and watchers (controlling thread's view).
  int object_count() const { return objects_by_id_.count(); }
  int watcher_count() const { return watchers_by_id_.count(); }
  /// Whether `id` names a registered object (false for a stale or unknown id). Controlling thread.
  bool contains(ObjectId id) const { return find_object(id) != nullptr; }
  /// The tree of a registered object (the id must be valid: see contains()). Controlling thread.
  const SphereTree& tree(ObjectId id) const;

 private:
  struct Object;
  struct Watcher;
  // Ids to items: core's slot table under this world's id type (slot in the low bits, generation
  // above), changed by the controlling thread and looked up lock-free by movers and readers
  // (defined in the .cpp, the only user).
  template <typename T>
  class SlotTable {
   public:
    explicit SlotTable(int capacity);
    std::int32_t next_id() const;    // the id occupy() gives next; -1 when the table is full
    void occupy(T* item);            // at next_id()
    void release(std::int32_t id);   // the id and its copies are stale from now on
    T* find(std::int32_t id) const;  // null for a stale or unknown id
    T* at_slot(std::int32_t slot) const {
      return slots_.item(static_cast<std::uint32_t>(slot)).load(std::memory_order_acquire);
    }
    std::int32_t slots_used() const { return static_cast<std::int32_t>(slots_.slots_used()); }
    std::uint32_t generation(std::int32_t slot) const { return slots_.generation(static_cast<std::uint32_t>(slot)); }
    int count() const { return slots_.count(); }

   private:
    core::SlotTable<std::atomic<T*>> slots_;
  };
  // a change for the collision thread, and what it hands back to be freed
  struct Change {
    enum class Kind : std::uint8_t { kAddObject, kRemoveObject, kAddWatcher, kRemoveWatcher } kind;
    Object* object = nullptr;
    Watcher* watcher = nullptr;
  };

  Object* find_object(ObjectId id) const;
  // the contact margin of a pair of objects: the world's and each one's extra margin [m]
  double pair_margin(const Object& a, const Object& b) const;
  Watcher* find_watcher(WatcherId id) const;
  Status stale_object_error(const char* what, ObjectId id) const;
  Status submit(const Change& change);
  void apply(const Change& change);
  void apply_pending();
  void free_retired();
  Result<WatcherId> add_watcher(Object* a, Object* b);
  void run_step(double time_s);
  void update_broad_phase(Object& object);
  void query_pair(Watcher& watcher, ContactFrame& frame);
  void query_tool(Watcher& watcher, ContactFrame& frame);

  CollisionWorldOptions options_;
  // controlling thread: the registry
  SlotTable<Object> objects_by_id_;
  SlotTable<Watcher> watchers_by_id_;
  SpscQueue<Change> changes_;  // controlling thread -> collision thread
  SpscQueue<Change> retired_;  // collision thread -> controlling thread (to free)
  // collision thread (or the controlling thread while it does not run)
  std::vector<Object*> objects_;
  std::vector<Object*> slot_objects_;  // by slot: the broad phase's proxies name slots
  std::vector<Watcher*> watchers_;
  std::vector<Object*> moving_;         // objects whose pose may change
  std::vector<Object*> candidates_;     // a tool watcher's broad-phase result
  std::vector<Change> retire_backlog_;  // retired but not yet handed back (queue full)
  DynamicAabbTree broad_phase_;
  OnCollision on_collision_;
  Delegator<double> on_step_;
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
  EventCounter broad_phase_candidates_;
  EventCounter stale_poses_;
  std::atomic<std::int64_t> last_pairs_{0};
  std::atomic<std::int64_t> max_pairs_{0};
  std::atomic<std::int32_t> live_objects_{0};
  std::atomic<std::int32_t> live_watchers_{0};
  std::atomic<std::int64_t> frame_bytes_{0};
};

}  // namespace uh::collette
