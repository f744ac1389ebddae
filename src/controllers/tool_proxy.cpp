#include "uh/controllers/tool_proxy.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "uh/core/atomic_max.hpp"
#include "uh/forcecomp/virtual_coupling.hpp"

namespace uh::controllers {
namespace {

// The tool's extent about its own origin: the farthest point of its root sphere [m].
double tool_radius(const collette::SphereTree& tree) {
  if (tree.empty()) return 0.01;
  const collette::SphereTreeNode& root = tree.root();
  const Vec3 c{static_cast<double>(root.x), static_cast<double>(root.y), static_cast<double>(root.z)};
  const double r = norm(c) + static_cast<double>(root.radius);
  return r > 0.0 ? r : 0.01;
}

Vec3 centre(const Sphere& s) { return {static_cast<double>(s.x), static_cast<double>(s.y), static_cast<double>(s.z)}; }

// The rotation of a rotation vector (axis times angle).
Quat quat_from_rotation_vector(const Vec3& w) {
  const double angle = norm(w);
  return angle > 0.0 ? quat_from_axis_angle(w / angle, angle) : Quat{};
}

// The step from `from` to `target` as a translation t and a rotation vector w, shortened so that
// no point of the tool moves farther than sqrt(2) * limit (|t| + R |w| <= sqrt(2) |(t, R w)|).
// Returns |(t, R w)| before shortening.
double wanted_step_of(const Pose& from, const Pose& target, double radius, double limit, Vec3& t, Vec3& w) {
  t = target.position - from.position;
  w = forcecomp::rotation_vector(target.rotation * conjugate(from.rotation));
  const double length = std::sqrt(squared_norm(t) + radius * radius * squared_norm(w));
  if (length > limit) {
    t = t * (limit / length);
    w = w * (limit / length);
  }
  return length;
}

// Moves `t` out along the normal of each constraint it breaks (with the rotation `w`), a few
// Gauss-Seidel sweeps over the rows: each correction meets its row exactly and is as short as it
// can be, so a step that breaks rows by rounding or a slight tilt keeps its tangential part.
void push_out(std::span<const forcecomp::ProxyConstraint> rows, const Vec3& w, Vec3& t) {
  for (int sweep = 0; sweep < 4; ++sweep) {
    bool met = true;
    for (const forcecomp::ProxyConstraint& c : rows) {
      const double at_t = dot(c.normal, t) + dot(cross(c.lever, c.normal), w) + c.gap;
      if (at_t >= -1e-12) continue;
      t -= at_t * c.normal;
      met = false;
    }
    if (met) return;
  }
}

// Coulomb friction on the proxy's translation (the god-object's friction cone). `from` is where the
// proxy was, `free` the translation the constraints allow towards the handle without friction, `n`
// the surface's normal. The proxy keeps its place along the surface (it takes only the normal part
// of the step) while the handle pulls it sideways by at most mu_s (mu_d once sliding) times how deep
// the handle presses; beyond, it slides until the pull is mu_d times the depth. The result is moved
// out along the normals of the constraints it breaks (the cone's normal is the contact's mean, so
// on a face of many rows a tangential step breaks the slightly tilted ones by micrometres), and
// what still breaks one after a few sweeps back towards `free` as far as a constraint needs (each
// is linear in it, and `free` meets them).
Vec3 friction_step(const Vec3& from, const Vec3& free, const Vec3& handle, const Vec3& n, double mu_s, double mu_d,
                   bool& sliding, std::span<const forcecomp::ProxyConstraint> rows, const Vec3& w) {
  const Vec3 normal_part = dot(free, n) * n;
  const Vec3 e = handle - (from + normal_part);
  const double depth = -dot(e, n);
  if (!(depth > 0.0)) {
    sliding = false;
    return free;
  }
  const Vec3 pull = e + depth * n;  // the handle's offset along the surface
  const double pull_length = norm(pull);
  Vec3 t = normal_part;
  sliding = pull_length > (sliding ? mu_d : mu_s) * depth;
  if (sliding) {
    Vec3 move = pull * (1.0 - mu_d * depth / pull_length);
    const double cap = norm(free - normal_part);  // no farther than the frictionless step
    if (norm(move) > cap) move = move * (cap / norm(move));
    t += move;
  }
  push_out(rows, w, t);
  double back = 0.0;
  for (const forcecomp::ProxyConstraint& c : rows) {
    const double turn = dot(cross(c.lever, c.normal), w) + c.gap;
    const double at_t = dot(c.normal, t) + turn;
    if (at_t >= -1e-12) continue;  // met, up to rounding (an active row is met exactly)
    const double at_free = dot(c.normal, free) + turn;
    back = at_free > at_t ? std::max(back, -at_t / (at_free - at_t)) : 1.0;
  }
  return t + std::min(back, 1.0) * (free - t);
}


}  // namespace

ToolProxy::ToolProxy(collette::CollisionWorld& world, collette::ObjectId tool, const collette::SphereTree& tool_tree,
                     const ToolProxyOptions& options, bool rotate)
    : world_(&world),
      tool_(tool),
      options_(options),
      solver_({.radius_m = tool_radius(tool_tree),
               .rotate = rotate,
               .max_constraints = std::max<std::int32_t>(options.max_constraints, 16) +
                                  2 * (1 + kCreaseRows) * tool_tree.leaf_count()}),
      slide_solver_({.radius_m = tool_radius(tool_tree), .rotate = rotate, .max_constraints = 6}),
      pair_capacity_(std::max<std::int32_t>(options.max_constraints, 16)),
      // after the pairs: a smooth or surface row per tool sphere and object near it (two objects at
      // most), and a surface's crease rows
      constraints_(static_cast<std::size_t>(pair_capacity_ + 2 * (1 + kCreaseRows) * tool_tree.leaf_count())),
      smooth_(static_cast<std::size_t>(tool_tree.leaf_count())) {
  touched_.reserve(static_cast<std::size_t>(tool_tree.leaf_count()));
}

void ToolProxy::bind() {
  texture_contact_.assign(watched_.size(), TextureContact{});
  contact_rows_.assign(watched_.size(), 0);
  const std::size_t slots = smooth_.size() * watched_.size();
  surface_seen_.assign(slots, 0);
  near_surface_.reserve(slots);
  collision_connection_ = world_->on_collision().connect<&ToolProxy::on_collision>(*this);
  step_connection_ = world_->on_step().connect<&ToolProxy::on_step>(*this);
}

std::int32_t ToolProxy::watched_index(std::int32_t object) const {
  for (std::size_t i = 0; i < watched_.size(); ++i)
    if (watched_[i].id == object) return static_cast<std::int32_t>(i);
  return -1;
}

void ToolProxy::on_collision(collette::ObjectId, collette::ObjectId b, const ContactFrame& frame) {
  if (b != tool_) return;
  for (const ContactSection& section : frame.sections())
    if (watched_index(section.object_a) >= 0) add_section(frame, section);
}

// Each leaf pair of the section becomes a constraint: the gap between its spheres (less what the
// proxy may sink) may close, no more, along the line of their centres.
void ToolProxy::add_section(const ContactFrame& frame, const ContactSection& section) {
  queried_ = section.world_from_b;
  have_query_ = true;
  const std::int32_t tag = watched_index(section.object_a);
  WatchedObject& watched = watched_[static_cast<std::size_t>(tag)];
  watched.world_from_object = section.world_from_a;
  const ProxyContact& contact = watched.contact;
  const bool textured = contact.object_texture.kind != forcecomp::TextureKind::kNone ||
                        contact.tool_texture.kind != forcecomp::TextureKind::kNone;
  const Pose object_from_world = inverse(section.world_from_a);
  const Pose tool_from_world = inverse(section.world_from_b);
  const auto pairs = frame.pairs().subspan(static_cast<std::size_t>(section.first_pair),
                                           static_cast<std::size_t>(section.pair_count));
  const std::int32_t capacity = pair_capacity_;
  const auto heap_end = constraints_.begin() + capacity;
  for (const SpherePairContact& p : pairs) {
    if (!seated_ && p.volume > 0.f) {
      inside_ = true;  // begun inside: no side to keep yet, the constraints are not needed
      return;
    }
    const Vec3 a = transform_point(section.world_from_a, centre(p.sphere_a_local));
    const Vec3 b = transform_point(section.world_from_b, centre(p.sphere_b_local));
    const double distance = norm(b - a);
    const Vec3 n = distance > 1e-12 ? (b - a) / distance
                                    : Vec3{static_cast<double>(p.normal_world[0]), static_cast<double>(p.normal_world[1]),
                                           static_cast<double>(p.normal_world[2])};
    const double rb = static_cast<double>(p.sphere_b_local.radius);
    double gap = distance - static_cast<double>(p.sphere_a_local.radius) - rb + options_.penetration_m;
    if (textured && !contact.surface) {
      // the relief where the pair touches, on the object's sphere and on the tool's (an object with
      // a mesh surface has its relief at one point, on all its rows: texture_rows)
      const Vec3 on_object = a + static_cast<double>(p.sphere_a_local.radius) * n;
      gap -= forcecomp::texture_height(contact.object_texture, transform_point(object_from_world, on_object)) +
             forcecomp::texture_height(contact.tool_texture, transform_point(tool_from_world, b - rb * n));
    }
    const forcecomp::ProxyConstraint c{.normal = n,
                                       .lever = (b - rb * n) - section.world_from_b.position,
                                       .gap = gap,
                                       .tag = tag};
    if (contact.surface) {
      add_to_surface(p.leaf_b, tag, b, rb);
      // a pair farther than a step (reported for the mesh above the spheres) cannot bind
      if (gap - options_.penetration_m > options_.step_m) continue;
    } else if (options_.smoothing_m > 0.0) {
      add_to_smooth(p.leaf_b, b, rb, n, gap - options_.penetration_m, c.tag);
    }
    // beyond the capacity the nearest pairs are kept (a heap on the gap, largest on top); the step
    // shrinks to the smallest gap left out
    const auto by_gap = [](const forcecomp::ProxyConstraint& x, const forcecomp::ProxyConstraint& y) {
      return x.gap < y.gap;
    };
    if (constraint_count_ < capacity) {
      constraints_[static_cast<std::size_t>(constraint_count_++)] = c;
      std::push_heap(constraints_.begin(), constraints_.begin() + constraint_count_, by_gap);
    } else if (gap < constraints_.front().gap) {
      dropped_gap_m_ = std::min(dropped_gap_m_, constraints_.front().gap);
      std::pop_heap(constraints_.begin(), heap_end, by_gap);
      *(heap_end - 1) = c;
      std::push_heap(constraints_.begin(), heap_end, by_gap);
    } else {
      dropped_gap_m_ = std::min(dropped_gap_m_, gap);
    }
  }
}

// The soft minimum of a tool sphere's gaps to the object's spheres near it, -e log sum exp(-d_i / e)
// (e = smoothing_m), is never more than the smallest gap and is smooth where the smallest one has
// kinks (between the caps of a packed face): summed here pair by pair, a constraint per tool sphere.
void ToolProxy::add_to_smooth(std::int32_t leaf, const Vec3& centre_world, double radius, const Vec3& normal,
                              double gap, std::int32_t tag) {
  if (leaf < 0 || static_cast<std::size_t>(leaf) >= smooth_.size()) return;
  SmoothLeaf& s = smooth_[static_cast<std::size_t>(leaf)];
  if (s.weight == 0.0) {
    touched_.push_back(leaf);  // reserved for every leaf: no allocation
    s.centre = centre_world;
    s.radius = radius;
    s.tag = tag;
  }
  const double w = std::exp(-gap / options_.smoothing_m);
  s.weight += w;
  s.gradient += w * normal;
}

// The smooth constraints, after the pairs' (the heap's order no longer matters); on_step clears the sums.
void ToolProxy::append_smooth(const Pose& proxy) {
  for (const std::int32_t leaf : touched_) {
    SmoothLeaf& s = smooth_[static_cast<std::size_t>(leaf)];
    const Vec3 gradient = s.gradient / s.weight;  // d(soft gap)/d(position of the tool sphere)
    const double length = norm(gradient);
    const double soft_gap = -options_.smoothing_m * std::log(s.weight);
    if (length > 1e-9 && constraint_count_ < static_cast<std::int32_t>(constraints_.size())) {
      const Vec3 n = gradient / length;
      constraints_[static_cast<std::size_t>(constraint_count_++)] = {
          .normal = n, .lever = (s.centre - s.radius * n) - proxy.position,
          .gap = (soft_gap + options_.penetration_m) / length,
          .tag = s.tag};
    }
  }
}

// A tool sphere near an object with a mesh surface, once per step and object.
void ToolProxy::add_to_surface(std::int32_t leaf, std::int32_t tag, const Vec3& centre_world, double radius) {
  if (leaf < 0 || static_cast<std::size_t>(leaf) >= smooth_.size()) return;
  const std::size_t slot = static_cast<std::size_t>(leaf) * watched_.size() + static_cast<std::size_t>(tag);
  if (slot >= surface_seen_.size() || surface_seen_[slot] != 0) return;  // watched after bind(): no room
  surface_seen_[slot] = 1;
  near_surface_.push_back({.leaf = leaf, .tag = tag, .centre = centre_world, .radius = radius});  // reserved
}

// A row per tool sphere near a mesh surface: its centre stays its radius (less the allowed
// penetration) away from the surface's nearest point, along the line to it. The distance to a face
// is linear in the step and to a convex edge or corner convex, so the row is exact or conservative
// there. A centre found on the inner side of the nearest face (it began inside, or a saddle corner)
// gets no row: the sphere pairs hold it. In a concave crease or corner the nearest face is one of
// two or three the sphere touches, and which one flips as it moves: each face it lies squarely
// above (crease_rows) adds its own row. Textures then raise each object's rows (texture_contact).
void ToolProxy::append_surface(const Pose& proxy) {
  for (const SurfaceLeaf& near : near_surface_) {
    const WatchedObject& watched = watched_[static_cast<std::size_t>(near.tag)];
    const Vec3 p = transform_point(inverse(watched.world_from_object), near.centre);
    const double reach = near.radius + options_.step_m + options_.penetration_m;
    const collette::SurfacePoint q = watched.contact.surface->nearest(p, reach);
    if (!q.found || dot(p - q.point, q.face_normal) < 0.0) continue;
    const Vec3 n_object = q.distance > 1e-12 ? (p - q.point) / q.distance : q.face_normal;
    if (!add_surface_row(near, watched, n_object, q.distance, proxy.position)) break;
    TextureContact& t = texture_contact_[static_cast<std::size_t>(near.tag)];
    const Vec3 n = rotate(watched.world_from_object.rotation, n_object);
    const double gap = q.distance - near.radius + options_.penetration_m;
    if (gap < t.gap) t = {.gap = gap, .on_object = q.point, .on_tool = near.centre - near.radius * n};
    // the other faces' rows, once the nearest is within half a step: then they are too (none is
    // nearer), as a sphere's nearest face gets its row half a step before the sphere reaches it
    if (gap <= 0.5 * options_.step_m && !crease_rows(near, watched, p, reach, n_object, proxy.position)) break;
  }
  texture_rows({constraints_.data(), static_cast<std::size_t>(constraint_count_)});
}

// The row keeping a tool sphere `distance` from a surface along `n_object` (the object's frame);
// false when the rows are full.
bool ToolProxy::add_surface_row(const SurfaceLeaf& near, const WatchedObject& watched, const Vec3& n_object,
                                double distance, const Vec3& proxy_position) {
  if (constraint_count_ >= static_cast<std::int32_t>(constraints_.size())) return false;
  const Vec3 n = rotate(watched.world_from_object.rotation, n_object);
  constraints_[static_cast<std::size_t>(constraint_count_++)] = {.normal = n,
                                                                 .lever = (near.centre - near.radius * n) - proxy_position,
                                                                 .gap = distance - near.radius + options_.penetration_m,
                                                                 .tag = near.tag};
  return true;
}

// The other faces of a concave crease or corner: each face the sphere's centre lies squarely above
// (its foot inside the face, so the row is the face's plane, exact) whose normal is more than
// kCreaseAngle from the rows already there. A face's plane past its edges lies outside the object
// only at a convex edge, where the centre is not squarely above the far face; a flat face's
// triangles repeat one plane, so they add nothing. False when the rows are full.
bool ToolProxy::crease_rows(const SurfaceLeaf& near, const WatchedObject& watched, const Vec3& p, double reach,
                            const Vec3& nearest_normal, const Vec3& proxy_position) {
  constexpr double kCreaseAngle = 15.0 * kPi / 180.0;
  const double cos_crease = std::cos(kCreaseAngle);
  std::array<collette::SurfacePoint, kCreaseRows + 4> faces{};
  const std::size_t found = watched.contact.surface->faces_below(p, reach, faces, nearest_normal, kCreaseAngle);
  std::array<Vec3, kCreaseRows + 1> taken{nearest_normal};
  std::size_t count = 1;
  for (std::size_t i = 0; i < found && count < taken.size(); ++i) {
    const Vec3& n = faces[i].face_normal;
    bool repeat = false;
    for (std::size_t j = 0; j < count; ++j) repeat = repeat || dot(n, taken[j]) >= cos_crease;
    if (repeat) continue;
    if (!add_surface_row(near, watched, n, faces[i].distance, proxy_position)) return false;
    taken[count++] = n;
  }
  return true;
}

// A texture is felt where the contact is, as the penalty path's surface stage feels it: each
// object's rows are raised by its and the tool's texture heights at its nearest row's contact point
// (one point per object, so a large tool rides the relief under its contact point rather than
// bridging it). Its sphere pairs' rows too: raised each at its own point, the rows under a valley's
// neighbours held the tool up and it rode half the relief (a 2 mm grating of 71 um RMS on the
// packed slab: 30-38 um). Clears the contact points for the next step.
void ToolProxy::texture_rows(std::span<forcecomp::ProxyConstraint> rows) {
  const Pose tool_from_world = inverse(queried_);
  for (std::size_t tag = 0; tag < watched_.size(); ++tag) {
    TextureContact& t = texture_contact_[tag];
    const ProxyContact& contact = watched_[tag].contact;
    if (t.gap < std::numeric_limits<double>::infinity() && (contact.object_texture.kind != forcecomp::TextureKind::kNone ||
                                                             contact.tool_texture.kind != forcecomp::TextureKind::kNone)) {
      const double height = forcecomp::texture_height(contact.object_texture, t.on_object) +
                            forcecomp::texture_height(contact.tool_texture, transform_point(tool_from_world, t.on_tool));
      for (forcecomp::ProxyConstraint& c : rows)
        if (c.tag == static_cast<std::int32_t>(tag)) c.gap -= height;
    }
    t = {};
  }
}

// The contact's normal and friction from the constraints holding the proxy (the largest
// coefficients of the objects they are with); `active` indexes `rows`, or null: the first `count`.
ToolProxy::HoldingFriction ToolProxy::holding_friction(std::span<const forcecomp::ProxyConstraint> rows,
                                                       const std::int32_t* active, std::int32_t count) const {
  HoldingFriction h;
  Vec3 sum{};
  for (std::int32_t i = 0; i < count; ++i) {
    const forcecomp::ProxyConstraint& c = rows[static_cast<std::size_t>(active != nullptr ? active[i] : i)];
    sum += c.normal;
    if (c.tag >= 0 && static_cast<std::size_t>(c.tag) < watched_.size()) {
      const ProxyContact& contact = watched_[static_cast<std::size_t>(c.tag)].contact;
      h.friction_static = std::max(h.friction_static, contact.friction_static);
      h.friction_dynamic = std::max(h.friction_dynamic, contact.friction_dynamic);
      h.stiffness_n_m = std::max(h.stiffness_n_m, contact.stiffness_n_m);
    }
  }
  h.normal = norm(sum) > 0.0 ? normalized(sum) : Vec3{};
  return h;
}

// Per watched object, its rows in contact after the step (t, w): within a tenth of a millimetre of
// their allowed depth at the new pose, as contact_normal counts them. The rows the step leaves
// farther are apart, so a contact ends the step the proxy lifts off.
void ToolProxy::count_contacts(std::span<const forcecomp::ProxyConstraint> rows, const Vec3& t, const Vec3& w) {
  std::fill(contact_rows_.begin(), contact_rows_.end(), 0);
  for (const forcecomp::ProxyConstraint& c : rows) {
    // the normal points out of the object: a step along it opens the row (ProxyConstraint)
    const double gap_after = c.gap + dot(c.normal, t) + dot(cross(c.lever, c.normal), w);
    if (gap_after < 1e-4 && c.tag >= 0 && static_cast<std::size_t>(c.tag) < contact_rows_.size())
      ++contact_rows_[static_cast<std::size_t>(c.tag)];
  }
}

// The friction cone's normal: the mean normal of the rows in contact (within a tenth of a
// millimetre of their allowed depth), of the per-sphere rows (rows[first_per_sphere, end): the
// smoothed or the mesh surface's) when any of them is in contact, since the raw sphere pairs' normals
// scatter with the packing's grain by degrees, which tilts the cone from step to step, breaks a
// slide into stick and slip and made a packed face's dynamic friction read 12-25 % low; `holding`
// when none is in contact.
Vec3 ToolProxy::contact_normal(std::span<const forcecomp::ProxyConstraint> rows, std::size_t first_per_sphere,
                               const Vec3& holding) const {
  const auto mean_in_contact = [](std::span<const forcecomp::ProxyConstraint> some) {
    Vec3 sum{};
    for (const forcecomp::ProxyConstraint& c : some)
      if (c.gap < 1e-4) sum += c.normal;
    return sum;
  };
  const Vec3 per_sphere = mean_in_contact(rows.subspan(std::min(first_per_sphere, rows.size())));
  const Vec3 sum = norm(per_sphere) > 0.0 ? per_sphere : mean_in_contact(rows);
  return norm(sum) > 0.0 ? normalized(sum) : holding;
}

// One god-object step from `from` towards `target`: the wanted step, shortened so that no point of
// the tool moves farther than the pairs the step saw allow, projected onto the constraints.
Pose ToolProxy::advance(const Pose& from, const Pose& target, ProxyState& out) {
  const bool turns = solver_.options().rotate;
  const double radius = solver_.options().radius_m;
  const double reach = std::min(options_.step_m, std::max(dropped_gap_m_, 0.0));
  const double limit = reach / std::sqrt(2.0);
  Vec3 t, w;
  const double length = wanted_step(from, target, limit, t, w);
  // a point at lever r turns on an arc: it falls short of the chord's tangent by |w|^2 |r| / 2, at
  // most |(t, R w)|^2 / (2 R) whatever rotation the projection adds (solve_turning)
  const double worst_arc = std::min(length, limit) * std::min(length, limit) / (2.0 * radius);
  // the step moves no point farther than sqrt(2) |(t, R w)| (a projection onto constraints that the
  // step 0 meets is no longer than what it projects), so a pair with a larger gap cannot bind:
  // only the others go to the solver (a hand moving slowly sees a few of the margin's pairs)
  double deepest = 0.0;
  for (std::int32_t k = 0; k < constraint_count_; ++k)
    deepest = std::max(deepest, -constraints_[static_cast<std::size_t>(k)].gap);
  raise_max(deepest_m_, deepest);
  const double moves = (deepest > 0.0 ? reach : std::sqrt(2.0) * std::min(length, limit)) + worst_arc;
  std::int32_t kept = 0, kept_pairs = 0;
  for (std::int32_t k = 0; k < constraint_count_; ++k)
    if (constraints_[static_cast<std::size_t>(k)].gap < moves) {
      constraints_[static_cast<std::size_t>(kept++)] = constraints_[static_cast<std::size_t>(k)];
      if (k < pair_rows_) kept_pairs = kept;
    }
  const std::span<forcecomp::ProxyConstraint> rows{constraints_.data(), static_cast<std::size_t>(kept)};
  forcecomp::ProxyStep step{.translation = t, .rotation = w};
  if (!rows.empty()) {
    const auto started = std::chrono::steady_clock::now();
    step = solve_turning(rows, t, w, worst_arc);
    solve_time_.record(static_cast<std::uint64_t>(
        std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - started).count()));
    if (!step.converged) unsolved_.fetch_add(1, std::memory_order_relaxed);
    if (step.active > 0) contact_updates_.fetch_add(1, std::memory_order_relaxed);
    // from too deep the projection may be longer than the bound: the rest waits for the next step
    const double moved = std::sqrt(squared_norm(step.translation) + radius * radius * squared_norm(step.rotation));
    if (moved > limit) {
      step.translation = step.translation * (limit / moved);
      step.rotation = step.rotation * (limit / moved);
    }
  }
  HoldingFriction held = holding_friction(rows, step.active_index, rows.empty() ? 0 : step.active);
  out.friction_static = held.friction_static;
  out.friction_dynamic = held.friction_dynamic;
  out.stiffness_n_m = held.stiffness_n_m;
  if (held.friction_static > 0.0)
    held.normal = contact_normal(rows, static_cast<std::size_t>(kept_pairs), held.normal);
  out.contact_normal = held.normal;
  const Vec3 solved = step.translation;
  if (step.active > 0 && held.friction_static > 0.0 && norm(held.normal) > 0.0)
    step.translation = friction_step(from.position, step.translation, target.position, held.normal,
                                     held.friction_static, held.friction_dynamic, sliding_, rows,
                                     turns ? step.rotation : w);
  else
    sliding_ = false;
  out.sliding = sliding_;
  const Quat turn = quat_from_rotation_vector(turns ? step.rotation : w);
  Pose next;
  next.position = from.position + step.translation;
  next.rotation = normalized(turn * from.rotation);
  count_contacts(rows, step.translation, turns ? step.rotation : w);
  // the constraints that held the solved step, carried to the new pose: met exactly there unless
  // friction kept the proxy from the solved step, open then by what it kept it from (given them
  // closed, a sticking proxy's slide on the haptic thread lifted it off a packed face by 0.035 mm,
  // a 0.044 N jump felt while nothing moved)
  out.active = 0;
  const Vec3 held_back = step.translation - solved;
  for (std::int32_t i = 0; i < step.active && !rows.empty(); ++i) {
    const forcecomp::ProxyConstraint& c = rows[static_cast<std::size_t>(step.active_index[i])];
    out.holding[out.active++] = {
        .normal = c.normal, .lever = rotate(turn, c.lever), .gap = std::max(dot(c.normal, held_back), 0.0)};
  }
  out.reach_m = options_.step_m;
  return next;
}

// Solves the step with every gap less the arc its rotation sags by (|w|^2 R / 2 for the rotation w
// it turns out to take): first assuming the wanted rotation's, then, if the projection turned the
// tool farther, that rotation's with room to spare, and at last the bound `worst_arc` that holds
// for any projection. A step that does not turn keeps its gaps whole, so a tool pressed straight
// onto a face rests where the constraints say, not an arc's sag above it.
forcecomp::ProxyStep ToolProxy::solve_turning(std::span<forcecomp::ProxyConstraint> rows, const Vec3& t,
                                              const Vec3& w, double worst_arc) {
  const double radius = solver_.options().radius_m;
  double arc = 0.5 * radius * squared_norm(w);
  double taken = 0.0;  // the arc the rows' gaps are lowered by now
  forcecomp::ProxyStep step;
  for (int attempt = 0; attempt < 3; ++attempt) {
    for (forcecomp::ProxyConstraint& c : rows) c.gap -= arc - taken;
    taken = arc;
    step = solver_.solve(rows, t, w);
    const double sag = 0.5 * radius * squared_norm(step.rotation);
    if (sag <= arc + 1e-12) break;
    arc = attempt == 0 ? std::min(2.0 * sag, worst_arc) : worst_arc;
  }
  return step;
}

double ToolProxy::wanted_step(const Pose& from, const Pose& target, double limit, Vec3& t, Vec3& w) const {
  return wanted_step_of(from, target, solver_.options().radius_m, limit, t, w);
}

Pose ToolProxy::slide(const ProxyState& state, const Pose& world_from_handle_tool) {
  Vec3 t, w;
  wanted_step(state.world_from_proxy, world_from_handle_tool, state.reach_m / std::sqrt(2.0), t, w);
  const std::span<const forcecomp::ProxyConstraint> holding{state.holding, static_cast<std::size_t>(state.active)};
  forcecomp::ProxyStep step = state.active > 0 ? slide_solver_.solve(holding, t, w)
                                               : forcecomp::ProxyStep{.translation = t, .rotation = w};
  if (state.active > 0 && state.friction_static > 0.0) {
    bool sliding = state.sliding;
    if (norm(state.contact_normal) > 0.0)
      step.translation = friction_step(state.world_from_proxy.position, step.translation,
                                       world_from_handle_tool.position, state.contact_normal, state.friction_static,
                                       state.friction_dynamic, sliding, holding, step.rotation);
  }
  Pose out;
  out.position = state.world_from_proxy.position + step.translation;
  out.rotation = normalized(quat_from_rotation_vector(step.rotation) * state.world_from_proxy.rotation);
  return out;
}

Pose ToolProxy::towards(const Pose& from, const Pose& to, double reach_m) const {
  Vec3 t, w;
  const double limit = reach_m / std::sqrt(2.0);
  // within reach: `to` itself (rebuilt from the step, its turn would be off by rounding, and a torque
  // sent where none is)
  if (wanted_step(from, to, limit, t, w) <= limit) return to;
  return {.rotation = normalized(quat_from_rotation_vector(w) * from.rotation), .position = from.position + t};
}

void ToolProxy::on_step(double time_s) {
  const bool fresh = target_.update();
  if (!fresh && !placed_) return;
  const Pose& target = target_.read_buffer();
  if (constraint_count_ == pair_capacity_)
    capped_steps_.fetch_add(1, std::memory_order_relaxed);
  ProxyState& out = state_.write_buffer();
  out.active = 0;
  out.reach_m = options_.step_m;
  out.follows_handle = false;
  // the tool appears where the handle is, as without a proxy; if that is inside an object it has no
  // side to keep, so it follows the handle freely (zero force) until it is out of every object
  const bool inside = inside_;
  inside_ = false;
  if (!placed_ || (!seated_ && inside)) {
    proxy_ = target;
    out.follows_handle = true;
    if (placed_) free_updates_.fetch_add(1, std::memory_order_relaxed);
    placed_ = true;
  } else {
    seated_ = true;
    const Pose from = have_query_ ? queried_ : proxy_;
    pair_rows_ = constraint_count_;
    append_smooth(from);
    append_surface(from);
    proxy_ = advance(from, target, out);
  }
  for (const SurfaceLeaf& near : near_surface_)
    surface_seen_[static_cast<std::size_t>(near.leaf) * watched_.size() + static_cast<std::size_t>(near.tag)] = 0;
  near_surface_.clear();
  // the sums start again next step (whether or not this one used them)
  for (const std::int32_t leaf : touched_) smooth_[static_cast<std::size_t>(leaf)] = {};
  touched_.clear();
  raise_max(max_constraints_, constraint_count_);
  out.world_from_proxy = proxy_;
  out.time_s = time_s;
  out.constraints = constraint_count_;
  state_.publish();
  world_->set_pose(tool_, proxy_);
  updates_.fetch_add(1, std::memory_order_relaxed);
  constraint_count_ = 0;
  dropped_gap_m_ = std::numeric_limits<double>::infinity();
  have_query_ = false;
}

ToolProxyStats ToolProxy::stats() const {
  ToolProxyStats s;
  s.updates = updates_.load(std::memory_order_relaxed);
  s.contact_updates = contact_updates_.load(std::memory_order_relaxed);
  s.unsolved = unsolved_.load(std::memory_order_relaxed);
  s.capped_steps = capped_steps_.load(std::memory_order_relaxed);
  s.free_updates = free_updates_.load(std::memory_order_relaxed);
  s.max_constraints = max_constraints_.load(std::memory_order_relaxed);
  s.deepest_m = deepest_m_.load(std::memory_order_relaxed);
  s.solve_time = solve_time_.summary();
  return s;
}

}  // namespace uh::controllers
