#include "uh/collette/dynamic_aabb_tree.hpp"

#include <cassert>
#include <cstdlib>

namespace uh::collette {

DynamicAabbTree::DynamicAabbTree(std::int32_t reserve) {
  nodes_.reserve(static_cast<std::size_t>(std::max(reserve, 1)));
  stack_.reserve(256);
}

std::int32_t DynamicAabbTree::allocate_node() {
  if (free_ == kNull) {
    nodes_.emplace_back();
    return static_cast<std::int32_t>(nodes_.size() - 1);
  }
  const std::int32_t id = free_;
  free_ = nodes_[static_cast<std::size_t>(id)].parent;
  nodes_[static_cast<std::size_t>(id)] = Node{};
  return id;
}

void DynamicAabbTree::free_node(std::int32_t id) {
  Node& n = nodes_[static_cast<std::size_t>(id)];
  n = Node{};
  n.parent = free_;
  free_ = id;
}

std::int32_t DynamicAabbTree::create(const Aabb& box, double margin, std::int32_t user) {
  const std::int32_t id = allocate_node();
  Node& n = nodes_[static_cast<std::size_t>(id)];
  n.box = aabb::grown(box, margin);
  n.user = user;
  n.height = 0;
  insert_leaf(id);
  ++proxy_count_;
  return id;
}

void DynamicAabbTree::destroy(std::int32_t proxy) {
  assert(nodes_[static_cast<std::size_t>(proxy)].is_leaf());
  remove_leaf(proxy);
  free_node(proxy);
  --proxy_count_;
}

bool DynamicAabbTree::move(std::int32_t proxy, const Aabb& box, double margin) {
  if (aabb::contains(nodes_[static_cast<std::size_t>(proxy)].box, box)) return false;
  remove_leaf(proxy);
  nodes_[static_cast<std::size_t>(proxy)].box = aabb::grown(box, margin);
  insert_leaf(proxy);
  return true;
}

void DynamicAabbTree::insert_leaf(std::int32_t leaf) {
  if (root_ == kNull) {
    root_ = leaf;
    nodes_[static_cast<std::size_t>(leaf)].parent = kNull;
    return;
  }
  // the best sibling by the surface-area heuristic: descend while a child's cost (its growth plus
  // the growth the new leaf causes in all ancestors) beats making the current node the sibling
  const Aabb leaf_box = nodes_[static_cast<std::size_t>(leaf)].box;
  std::int32_t index = root_;
  while (!nodes_[static_cast<std::size_t>(index)].is_leaf()) {
    const Node& n = nodes_[static_cast<std::size_t>(index)];
    const double area = aabb::half_area(n.box);
    const double combined = aabb::half_area(aabb::merged(n.box, leaf_box));
    const double cost = 2.0 * combined;                  // a new parent of this node and the leaf
    const double inheritance = 2.0 * (combined - area);  // the growth of this node's box
    const auto child_cost = [&](std::int32_t c) {
      const Node& child = nodes_[static_cast<std::size_t>(c)];
      const double merged = aabb::half_area(aabb::merged(child.box, leaf_box));
      return child.is_leaf() ? merged + inheritance : merged - aabb::half_area(child.box) + inheritance;
    };
    const double cost1 = child_cost(n.child1);
    const double cost2 = child_cost(n.child2);
    if (cost < cost1 && cost < cost2) break;
    index = cost1 < cost2 ? n.child1 : n.child2;
  }
  const std::int32_t sibling = index;
  const std::int32_t old_parent = nodes_[static_cast<std::size_t>(sibling)].parent;
  const std::int32_t new_parent = allocate_node();  // may reallocate nodes_: index afresh below
  {
    Node& p = nodes_[static_cast<std::size_t>(new_parent)];
    p.parent = old_parent;
    p.box = aabb::merged(leaf_box, nodes_[static_cast<std::size_t>(sibling)].box);
    p.height = nodes_[static_cast<std::size_t>(sibling)].height + 1;
    p.child1 = sibling;
    p.child2 = leaf;
  }
  if (old_parent != kNull) {
    Node& op = nodes_[static_cast<std::size_t>(old_parent)];
    (op.child1 == sibling ? op.child1 : op.child2) = new_parent;
  } else {
    root_ = new_parent;
  }
  nodes_[static_cast<std::size_t>(sibling)].parent = new_parent;
  nodes_[static_cast<std::size_t>(leaf)].parent = new_parent;

  // refit and rebalance the ancestors
  for (std::int32_t i = nodes_[static_cast<std::size_t>(leaf)].parent; i != kNull;
       i = nodes_[static_cast<std::size_t>(i)].parent) {
    i = balance(i);
    Node& n = nodes_[static_cast<std::size_t>(i)];
    const Node& c1 = nodes_[static_cast<std::size_t>(n.child1)];
    const Node& c2 = nodes_[static_cast<std::size_t>(n.child2)];
    n.height = 1 + std::max(c1.height, c2.height);
    n.box = aabb::merged(c1.box, c2.box);
  }
}

void DynamicAabbTree::remove_leaf(std::int32_t leaf) {
  if (leaf == root_) {
    root_ = kNull;
    return;
  }
  const std::int32_t parent = nodes_[static_cast<std::size_t>(leaf)].parent;
  const Node& p = nodes_[static_cast<std::size_t>(parent)];
  const std::int32_t grand = p.parent;
  const std::int32_t sibling = p.child1 == leaf ? p.child2 : p.child1;
  if (grand == kNull) {
    root_ = sibling;
    nodes_[static_cast<std::size_t>(sibling)].parent = kNull;
    free_node(parent);
    return;
  }
  Node& g = nodes_[static_cast<std::size_t>(grand)];
  (g.child1 == parent ? g.child1 : g.child2) = sibling;
  nodes_[static_cast<std::size_t>(sibling)].parent = grand;
  free_node(parent);
  for (std::int32_t i = grand; i != kNull; i = nodes_[static_cast<std::size_t>(i)].parent) {
    i = balance(i);
    Node& n = nodes_[static_cast<std::size_t>(i)];
    const Node& c1 = nodes_[static_cast<std::size_t>(n.child1)];
    const Node& c2 = nodes_[static_cast<std::size_t>(n.child2)];
    n.box = aabb::merged(c1.box, c2.box);
    n.height = 1 + std::max(c1.height, c2.height);
  }
}

// A left or right rotation when the children's heights differ by more than one; returns the
// node now at a's place (b2DynamicTree::Balance).
std::int32_t DynamicAabbTree::balance(std::int32_t ia) {
  Node& a = nodes_[static_cast<std::size_t>(ia)];
  if (a.is_leaf() || a.height < 2) return ia;
  const std::int32_t ib = a.child1;
  const std::int32_t ic = a.child2;
  Node& b = nodes_[static_cast<std::size_t>(ib)];
  Node& c = nodes_[static_cast<std::size_t>(ic)];
  const std::int32_t skew = c.height - b.height;
  // the taller child rises to a's place; a takes its shorter grandchild
  const auto rotate_up = [&](std::int32_t ihigh, std::int32_t ilow) {
    Node& high = nodes_[static_cast<std::size_t>(ihigh)];
    Node& low = nodes_[static_cast<std::size_t>(ilow)];
    const std::int32_t i1 = high.child1;
    const std::int32_t i2 = high.child2;
    Node& n1 = nodes_[static_cast<std::size_t>(i1)];
    Node& n2 = nodes_[static_cast<std::size_t>(i2)];
    high.child1 = ia;
    high.parent = a.parent;
    a.parent = ihigh;
    if (high.parent != kNull) {
      Node& hp = nodes_[static_cast<std::size_t>(high.parent)];
      (hp.child1 == ia ? hp.child1 : hp.child2) = ihigh;
    } else {
      root_ = ihigh;
    }
    const bool keep_first = n1.height > n2.height;
    const std::int32_t kept = keep_first ? i1 : i2;
    const std::int32_t given = keep_first ? i2 : i1;
    high.child2 = kept;
    (a.child1 == ihigh ? a.child1 : a.child2) = given;
    nodes_[static_cast<std::size_t>(given)].parent = ia;
    a.box = aabb::merged(low.box, nodes_[static_cast<std::size_t>(given)].box);
    high.box = aabb::merged(a.box, nodes_[static_cast<std::size_t>(kept)].box);
    a.height = 1 + std::max(low.height, nodes_[static_cast<std::size_t>(given)].height);
    high.height = 1 + std::max(a.height, nodes_[static_cast<std::size_t>(kept)].height);
    return ihigh;
  };
  if (skew > 1) return rotate_up(ic, ib);
  if (skew < -1) return rotate_up(ib, ic);
  return ia;
}

std::int32_t DynamicAabbTree::check(std::int32_t id, std::int32_t parent, bool& ok) const {
  const Node& n = nodes_[static_cast<std::size_t>(id)];
  if (n.parent != parent) ok = false;
  if (n.is_leaf()) {
    if (n.height != 0) ok = false;
    return 1;
  }
  const std::int32_t leaves = check(n.child1, id, ok) + check(n.child2, id, ok);
  const Node& c1 = nodes_[static_cast<std::size_t>(n.child1)];
  const Node& c2 = nodes_[static_cast<std::size_t>(n.child2)];
  if (n.height != 1 + std::max(c1.height, c2.height)) ok = false;
  if (std::abs(c1.height - c2.height) > 1) ok = false;
  if (!aabb::contains(n.box, c1.box) || !aabb::contains(n.box, c2.box)) ok = false;
  return leaves;
}

bool DynamicAabbTree::valid() const {
  if (root_ == kNull) return proxy_count_ == 0;
  bool ok = true;
  const std::int32_t leaves = check(root_, kNull, ok);
  return ok && leaves == proxy_count_;
}

}  // namespace uh::collette
