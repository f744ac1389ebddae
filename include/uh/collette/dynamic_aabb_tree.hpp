#pragma once
/// \file
/// DynamicAabbTree: the collision world's broad phase over objects, a bounding-volume hierarchy
/// of axis-aligned boxes that objects enter, leave and move in at any time (after Box2D's
/// b2DynamicTree, E. Catto).
///
/// Each proxy stores a "fat" box: the object's tight box grown by a margin. A moved object whose
/// tight box still fits in its fat box keeps its place in the tree (move() returns false), so a
/// slowly moving tool re-inserts only every few steps. Inserting picks the sibling by the
/// surface-area heuristic (branch and bound over the tree) and rebalances with AVL-style
/// rotations on the way up, so the height stays O(log n).
///
/// Memory: nodes live in one pool that doubles when full (create() may allocate; query() never
/// does, given a reserved stack). Not thread-safe: one owner thread (the collision thread).

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "uh/collette/triangle_mesh.hpp"
#include "uh/core/math.hpp"

namespace uh::collette {

/// Box operations of the broad phase, on the Aabb of triangle_mesh.hpp ([min, max] per axis).
namespace aabb {
inline bool overlaps(const Aabb& a, const Aabb& b) {
  return a.min.x <= b.max.x && b.min.x <= a.max.x && a.min.y <= b.max.y && b.min.y <= a.max.y &&
         a.min.z <= b.max.z && b.min.z <= a.max.z;
}
/// Whether `outer` encloses `inner`.
inline bool contains(const Aabb& outer, const Aabb& inner) {
  return outer.min.x <= inner.min.x && outer.min.y <= inner.min.y && outer.min.z <= inner.min.z &&
         inner.max.x <= outer.max.x && inner.max.y <= outer.max.y && inner.max.z <= outer.max.z;
}
/// Half the surface area (the cost of the surface-area heuristic; the factor 2 changes no choice).
inline double half_area(const Aabb& a) {
  const Vec3 d = a.max - a.min;
  return d.x * d.y + d.y * d.z + d.z * d.x;
}
inline Aabb of_sphere(const Vec3& centre, double radius) {
  return {centre - Vec3{radius, radius, radius}, centre + Vec3{radius, radius, radius}};
}
inline Aabb merged(const Aabb& a, const Aabb& b) {
  return {{std::min(a.min.x, b.min.x), std::min(a.min.y, b.min.y), std::min(a.min.z, b.min.z)},
          {std::max(a.max.x, b.max.x), std::max(a.max.y, b.max.y), std::max(a.max.z, b.max.z)}};
}
inline Aabb grown(const Aabb& a, double margin) {
  return {a.min - Vec3{margin, margin, margin}, a.max + Vec3{margin, margin, margin}};
}
}  // namespace aabb

class DynamicAabbTree {
 public:
  static constexpr std::int32_t kNull = -1;

  explicit DynamicAabbTree(std::int32_t reserve = 64);

  /// Adds a proxy with tight box `box` grown by `margin` and a user value; returns its id.
  std::int32_t create(const Aabb& box, double margin, std::int32_t user);
  /// Removes a proxy (its id may be reused by a later create()).
  void destroy(std::int32_t proxy);
  /// Updates a proxy's tight box. Returns true when it left its fat box and was re-inserted
  /// (with the new box grown by `margin`); false when it still fits (nothing changes).
  bool move(std::int32_t proxy, const Aabb& box, double margin);

  /// Calls `visit(user)` for every proxy whose fat box overlaps `box`; `visit` returns false to
  /// stop. Uses the member stack (no allocation once it is large enough).
  template <typename Visit>
  void query(const Aabb& box, Visit&& visit) {
    if (root_ == kNull) return;
    stack_.clear();
    stack_.push_back(root_);
    while (!stack_.empty()) {
      const std::int32_t id = stack_.back();
      stack_.pop_back();
      const Node& n = nodes_[static_cast<std::size_t>(id)];
      if (!aabb::overlaps(n.box, box)) continue;
      if (n.is_leaf()) {
        if (!visit(n.user)) return;
      } else {
        stack_.push_back(n.child1);
        stack_.push_back(n.child2);
      }
    }
  }

  const Aabb& fat_box(std::int32_t proxy) const { return nodes_[static_cast<std::size_t>(proxy)].box; }
  std::int32_t user(std::int32_t proxy) const { return nodes_[static_cast<std::size_t>(proxy)].user; }
  /// Height of the tree (a leaf alone: 0; empty: -1).
  std::int32_t height() const { return root_ == kNull ? -1 : nodes_[static_cast<std::size_t>(root_)].height; }
  std::int32_t proxy_count() const { return proxy_count_; }
  /// Checks the structure (parents, heights, enclosing boxes); for tests.
  bool valid() const;
  /// Heap bytes of the node pool and the query stack.
  std::size_t memory_bytes() const {
    return nodes_.capacity() * sizeof(Node) + stack_.capacity() * sizeof(std::int32_t);
  }

 private:
  struct Node {
    Aabb box{};
    std::int32_t parent = kNull;  // also the next free node while on the free list
    std::int32_t child1 = kNull;
    std::int32_t child2 = kNull;
    std::int32_t height = -1;  // leaf 0, free -1
    std::int32_t user = -1;
    bool is_leaf() const { return child1 == kNull; }
  };

  std::int32_t allocate_node();
  void free_node(std::int32_t id);
  void insert_leaf(std::int32_t leaf);
  void remove_leaf(std::int32_t leaf);
  std::int32_t balance(std::int32_t a);
  std::int32_t check(std::int32_t id, std::int32_t parent, bool& ok) const;

  std::vector<Node> nodes_;
  std::int32_t root_ = kNull;
  std::int32_t free_ = kNull;
  std::int32_t proxy_count_ = 0;
  std::vector<std::int32_t> stack_;
};

}  // namespace uh::collette
