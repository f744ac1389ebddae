#pragma once
/// \file
/// ToolProxy: the 6-DOF god-object of one tool, moved on the collision thread. The tool in the
/// collision world is the proxy, not the handle: every collision step it moves towards the
/// handle's pose as far as the sphere pairs near it allow (forcecomp::ProxySolver), so it never
/// passes through a surface, however thin or however hard the hand pushes. The device then feels
/// the spring between the handle and the proxy (ForceController).
///
/// Why it cannot tunnel: the world delivers every leaf pair closer than its contact margin (set to
/// at least `step_m`), each becomes a linear constraint that is conservative for translation
/// (a sphere pair's distance is a convex function of the translation), and no point of the tool
/// moves by more than `step_m` in a step, so a pair the step did not see cannot be reached. The
/// rotation's curvature (a point moves on an arc, the constraint sees the chord's tangent) is taken
/// off every gap. Pairs beyond the constraint capacity shrink the step to their smallest gap.
/// Moving objects are taken at the poses of the step's query. A tool that appears inside an object
/// (the handle's first pose is there) has no side to keep: it follows the handle freely, with zero
/// force, until it is out of every object, and keeps its side from then on.
///
/// Threads: construct, watch() and bind() on the controlling thread before the threads start;
/// set_target() and take() on the haptic thread (the handle's side); on_collision() and on_step()
/// run on the collision thread, which is then the tool's only mover in the world. stats() from any
/// thread. The collision-thread path never allocates, locks, throws or logs.

#include <atomic>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "uh/collette/collision_world.hpp"
#include "uh/collette/mesh_inside.hpp"
#include "uh/core/contact.hpp"
#include "uh/core/delegator.hpp"
#include "uh/core/latency_histogram.hpp"
#include "uh/core/latest_value.hpp"
#include "uh/forcecomp/material.hpp"
#include "uh/forcecomp/proxy_solver.hpp"
#include "uh/scene/force_options.hpp"

namespace uh::controllers {

/// Options of a ToolProxy: described by the scene (uh/scene/force_options.hpp).
using uh::scene::ToolProxyOptions;

/// What a watched object is to the proxy (ToolProxy::watch). Plain data.
struct ProxyContact {
  /// Coulomb friction of the pair (forcecomp::combine_materials), rendered on the proxy as a
  /// friction cone: a stick point, breakaway at `friction_static`, sliding at `friction_dynamic`.
  double friction_static = 0.0;
  double friction_dynamic = 0.0;
  /// The pair's stiffness as the spring the device renders while the proxy rests on it [N/m]; 0:
  /// the coupling's. The session gives the gradient law's spring of a round tip, 2 pi r k (k the
  /// combined material stiffness, r the tool's largest inner sphere), so a soft material feels as
  /// soft through the proxy as through the penalty path; the passivity bound still caps it.
  double stiffness_n_m = 0.0;
  /// The textures of the pair (`object_texture` in the object's frame, `tool_texture` in the
  /// tool's, forcecomp::texture_height): each raises the surface the proxy rests on by its height
  /// where it touches (with a mesh surface: at the contact point, the nearest row's, for all the
  /// object's rows, so the proxy rides over the texture's relief under it).
  forcecomp::Texture object_texture{};
  forcecomp::Texture tool_texture{};
  /// The object's mesh surface in metres, in its own frame, or null. With it the proxy rests on the
  /// mesh itself: each tool sphere near the object is kept off the surface's nearest point, so a flat
  /// face is flat, not the packing's grain (the sphere pairs stay as constraints underneath, and the
  /// soft minimum is not needed). A tool sphere gets its mesh row once a pair puts it within the
  /// world's margin of the object's spheres, which lie up to the packing's surface gap G below the
  /// mesh: a tool approaching faster than (margin - G) a step may sink into the mesh by up to G
  /// (never into the spheres) for a step before the row pushes it out.
  std::shared_ptr<const collette::MeshInside> surface{};
};

/// The proxy as the haptic thread reads it. Plain data.
struct ProxyState {
  Pose world_from_proxy{};       ///< the proxy's pose, world frame
  double time_s = 0.0;           ///< time of the collision step that set it [s]
  std::int32_t constraints = 0;  ///< constraints of that step
  /// The constraints holding the proxy at the end of that step, about its new pose (gap 0: met
  /// exactly): between steps the haptic thread slides the proxy along them towards the handle.
  std::int32_t active = 0;
  forcecomp::ProxyConstraint holding[6] = {};
  double reach_m = 0.0;          ///< how far a point may move from the proxy before the next step [m]
  /// Placed at the handle, which began inside an object: no side to keep, and no force.
  bool follows_handle = false;
  /// Coulomb friction of the contact holding it (the object's and the tool's materials combined):
  /// the proxy keeps its place along the surface until the handle pulls it sideways by more than
  /// friction_static times how deep it presses, then trails it at friction_dynamic.
  double friction_static = 0.0;
  double friction_dynamic = 0.0;
  /// The stiffest ProxyContact::stiffness_n_m of the contacts holding it [N/m]; 0: none given.
  double stiffness_n_m = 0.0;
  bool sliding = false;          ///< broke away (the dynamic coefficient holds) or sticking
  /// The surface's normal the friction cone is about: the mean of the normals of every pair in
  /// contact, not only the few holding it, so that the packing's grain tilts it less [unit, world].
  Vec3 contact_normal{};
};

/// What the proxy did so far. Plain data.
struct ToolProxyStats {
  std::uint64_t updates = 0;           ///< collision steps that moved (or held) the proxy
  std::uint64_t contact_updates = 0;   ///< of which with at least one constraint active
  std::uint64_t unsolved = 0;          ///< steps whose constraints contradicted each other
  std::uint64_t capped_steps = 0;      ///< steps shortened because pairs exceeded max_constraints
  std::uint64_t free_updates = 0;      ///< steps it followed the handle freely, having begun inside an object
  std::int32_t max_constraints = 0;    ///< most constraints of one step
  double deepest_m = 0.0;              ///< deepest overlap of a constrained pair beyond penetration_m [m], >= 0
  LatencySummary solve_time;           ///< the solver's time per step with constraints [ns]
};

class ToolProxy {
 public:
  /// `tool_tree` gives the tool's extent (the length that weighs rotation against translation).
  /// `rotate`: 6-DOF (false: the proxy turns with the handle, constraints on its position only).
  ToolProxy(collette::CollisionWorld& world, collette::ObjectId tool, const collette::SphereTree& tool_tree,
            const ToolProxyOptions& options, bool rotate);
  ToolProxy(const ToolProxy&) = delete;
  ToolProxy& operator=(const ToolProxy&) = delete;

  /// Pairs with `object` constrain the proxy (others, such as other tools, pass through).
  /// Controlling thread, before bind().
  void watch(collette::ObjectId object, const ProxyContact& contact = {}) { watched_.push_back({object, contact}); }
  /// Connects to the world's OnCollision and OnStep. Controlling thread, before the threads start.
  void bind();

  /// Where the handle puts the tool now. Haptic thread; real-time safe.
  void set_target(const Pose& world_from_handle_tool) { target_.write(world_from_handle_tool); }
  /// The newest proxy if a newer one than the last call arrived, else null. Haptic thread.
  const ProxyState* take() { return state_.update() ? &state_.read_buffer() : nullptr; }

  /// OnCollision handler: the step's pairs with watched objects become constraints. Collision thread.
  void on_collision(collette::ObjectId a, collette::ObjectId b, const ContactFrame& frame);
  /// OnStep handler: solves, moves the proxy in the world, publishes it. Collision thread.
  void on_step(double time_s);

  /// The proxy of `state` slid towards the handle along the constraints that hold it, by at most
  /// its reach: what the device renders against between collision steps, so that the force
  /// follows the handle at the haptic rate (zero in free space). Haptic thread; real-time safe.
  Pose slide(const ProxyState& state, const Pose& world_from_handle_tool);
  /// `to`, or the pose one slide's reach (`reach_m`, ProxyState::reach_m) from `from` towards it:
  /// the rendered proxy, `from` the one rendered last tick, moves no farther a tick than a slide
  /// may move it (unless it follows the handle freely). At the step that frees the proxy (it slips
  /// off an edge with the spring stretched), the step's own move and a whole free slide otherwise
  /// add up on top of the last tick's slide, which a row held: the force fell by half as much
  /// again in that tick. Real-time safe.
  Pose towards(const Pose& from, const Pose& to, double reach_m) const;

  /// The objects watched, in watch() order, and how many of the last step's constraint rows with
  /// each are in contact at the proxy's new pose (0: apart). Collision thread, after on_step (an
  /// OnStep handler bound after bind()): the session's contact events come from here.
  std::size_t watched_count() const { return watched_.size(); }
  collette::ObjectId watched_object(std::size_t k) const { return watched_[k].id; }
  std::int32_t contact_rows(std::size_t k) const { return contact_rows_[k]; }

  ToolProxyStats stats() const;
  /// The proxy's pose. On the collision thread (after on_step: where it moved to), or while the
  /// collision thread does not run (before start, after stop).
  const Pose& pose() const { return proxy_; }
  const ToolProxyOptions& options() const { return options_; }
  /// The extent used to weigh rotation against translation [m].
  double radius_m() const { return solver_.options().radius_m; }

 private:
  std::int32_t watched_index(std::int32_t object) const;  // -1: not watched
  struct HoldingFriction {
    Vec3 normal{};
    double friction_static = 0.0;
    double friction_dynamic = 0.0;
    double stiffness_n_m = 0.0;
  };
  Vec3 contact_normal(std::span<const forcecomp::ProxyConstraint> rows, std::size_t first_per_sphere,
                      const Vec3& holding) const;
  void count_contacts(std::span<const forcecomp::ProxyConstraint> rows, const Vec3& t, const Vec3& w);
  HoldingFriction holding_friction(std::span<const forcecomp::ProxyConstraint> rows, const std::int32_t* active,
                                   std::int32_t count) const;
  void add_to_smooth(std::int32_t leaf, const Vec3& centre_world, double radius, const Vec3& normal, double gap,
                     std::int32_t tag);
  void append_smooth(const Pose& proxy);
  void add_to_surface(std::int32_t leaf, std::int32_t tag, const Vec3& centre_world, double radius);
  void append_surface(const Pose& proxy);
  struct SurfaceLeaf;
  struct WatchedObject;
  bool add_surface_row(const SurfaceLeaf& near, const WatchedObject& watched, const Vec3& n_object, double distance,
                       const Vec3& proxy_position);
  bool crease_rows(const SurfaceLeaf& near, const WatchedObject& watched, const Vec3& p, double reach,
                   const Vec3& nearest_normal, const Vec3& proxy_position);
  /// The most rows a tool sphere adds past its nearest face's, for the other faces of a crease or corner.
  static constexpr std::int32_t kCreaseRows = 2;
  void texture_rows(std::span<forcecomp::ProxyConstraint> rows);
  void add_section(const ContactFrame& frame, const ContactSection& section);
  Pose advance(const Pose& from, const Pose& target, ProxyState& out);
  forcecomp::ProxyStep solve_turning(std::span<forcecomp::ProxyConstraint> rows, const Vec3& t, const Vec3& w,
                                     double worst_arc);
  double wanted_step(const Pose& from, const Pose& target, double limit, Vec3& t, Vec3& w) const;

  collette::CollisionWorld* world_;
  collette::ObjectId tool_;
  ToolProxyOptions options_;
  forcecomp::ProxySolver solver_;        // collision thread
  forcecomp::ProxySolver slide_solver_;  // haptic thread (six constraints)
  struct WatchedObject {
    collette::ObjectId id;
    ProxyContact contact;
    Pose world_from_object{};  // collision thread: at this step's query
  };
  std::vector<WatchedObject> watched_;
  bool sliding_ = false;  // collision thread: the proxy broke away from its stick point
  ScopedConnection collision_connection_;
  ScopedConnection step_connection_;
  LatestValue<Pose> target_;       // haptic thread -> collision thread
  LatestValue<ProxyState> state_;  // collision thread -> haptic thread

  // collision thread
  // the pairs' constraints (a heap on the gap, pair_capacity_ of them at most), then the smooth ones
  std::int32_t pair_capacity_;
  std::vector<forcecomp::ProxyConstraint> constraints_;
  // the soft minimum's sums per tool sphere (SphereTree::leaves() order) and the spheres touched
  struct SmoothLeaf {
    double weight = 0.0;  // sum exp(-gap_i / e)
    Vec3 gradient{};      // sum exp(-gap_i / e) n_i
    Vec3 centre{};        // the tool sphere's centre, world frame [m]
    double radius = 0.0;
    std::int32_t tag = -1;
  };
  std::vector<SmoothLeaf> smooth_;
  std::vector<std::int32_t> touched_;
  // the tool spheres near an object with a mesh surface: (tool leaf, watched object) once per step
  struct SurfaceLeaf {
    std::int32_t leaf = -1;
    std::int32_t tag = -1;
    Vec3 centre{};  // world frame [m]
    double radius = 0.0;
  };
  std::vector<SurfaceLeaf> near_surface_;
  std::vector<std::uint8_t> surface_seen_;  // per (leaf, watched object): already in near_surface_
  // per watched object: its nearest mesh row's contact point this step, where its texture is felt
  struct TextureContact {
    double gap = std::numeric_limits<double>::infinity();
    Vec3 on_object{};  // object frame
    Vec3 on_tool{};    // world frame
  };
  std::vector<TextureContact> texture_contact_;
  std::vector<std::int32_t> contact_rows_;  // per watched object: rows in contact after the step
  std::int32_t constraint_count_ = 0;
  // constraints_[0, pair_rows_) are this step's sphere pairs, the rest one row per tool sphere (the
  // smoothed or the mesh surface's)
  std::int32_t pair_rows_ = 0;
  double dropped_gap_m_ = std::numeric_limits<double>::infinity();  // smallest gap left out for capacity
  bool placed_ = false;
  bool seated_ = false;          // it has been out of every object: from then on it keeps its side
  bool inside_ = false;          // before it is seated: this step's query found it overlapping
  Pose proxy_{};
  Pose queried_{};               // the tool pose this step's frames were queried at
  bool have_query_ = false;

  std::atomic<std::uint64_t> updates_{0};
  std::atomic<std::uint64_t> contact_updates_{0};
  std::atomic<std::uint64_t> unsolved_{0};
  std::atomic<std::uint64_t> capped_steps_{0};
  std::atomic<std::uint64_t> free_updates_{0};
  std::atomic<std::int32_t> max_constraints_{0};
  std::atomic<double> deepest_m_{0.0};
  LatencyHistogram solve_time_;
};

}  // namespace uh::controllers
