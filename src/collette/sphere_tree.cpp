#include "uh/collette/sphere_tree.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <string>
#include <vector>

namespace uh::collette {
namespace {

Error node_error(int node, const std::string& what) {
  return Error{"sphere tree: node " + std::to_string(node) + ": " + what};
}

bool finite_node(const SphereTreeNode& n) {
  return std::isfinite(n.x) && std::isfinite(n.y) && std::isfinite(n.z) && std::isfinite(n.radius) &&
         std::isfinite(n.volume);
}

double sphere_volume(double r) { return 4.0 / 3.0 * 3.14159265358979323846 * r * r * r; }

}  // namespace

SphereTree::SphereTree(std::vector<SphereTreeNode> nodes, std::vector<Sphere> leaves, int depth, int arity)
    : nodes_(std::move(nodes)), leaves_(std::move(leaves)), depth_(depth), arity_(arity) {
  derive();
}

double SphereTree::leaf_share(std::size_t i) const {
  const SphereTreeNode& node = nodes_[i];
  if (node.is_leaf() || node.count < 1 || node.first < 0 ||
      static_cast<std::size_t>(node.first) + static_cast<std::size_t>(node.count) > nodes_.size())
    return 0.0;
  int leaves = 0;
  for (int c = node.first; c < node.first + node.count; ++c) leaves += nodes_[static_cast<std::size_t>(c)].is_leaf() ? 1 : 0;
  return static_cast<double>(leaves) / node.count;
}

void SphereTree::derive() {
  const std::size_t n = nodes_.size();
  density_.resize(n);
  leaf_parent_volume_ = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const SphereTreeNode& node = nodes_[i];
    const double ball = sphere_volume(static_cast<double>(node.radius));
    if (!node.is_leaf()) leaf_parent_volume_ += ball * leaf_share(i);
    density_[i] = node.is_leaf() || !(ball > 0.0) ? 1.f : static_cast<float>(std::min(1.0, static_cast<double>(node.volume) / ball));
  }
  // the blocks are only built for well-formed child ranges; validate() reports the others and
  // the queries require a validated tree
  int widest = 1;
  std::vector<std::int32_t> block_of(n, -1);
  std::int32_t blocks = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const SphereTreeNode& node = nodes_[i];
    if (node.is_leaf()) continue;
    if (node.count < 0 || node.count > kMaxSphereTreeArity || node.first < 0 ||
        static_cast<std::size_t>(node.first) + static_cast<std::size_t>(node.count) > n)
      continue;
    widest = std::max(widest, node.count);
    block_of[i] = blocks++;
  }
  block_width_ = widest <= 4 ? 4 : 8;
  const auto w = static_cast<std::size_t>(block_width_);
  block_bounds_.assign(static_cast<std::size_t>(blocks) * 4 * w, 0.f);
  block_child_.assign(static_cast<std::size_t>(blocks) * w, 0);
  block_count_.assign(static_cast<std::size_t>(blocks), 0);
  block_leaf_mask_.assign(static_cast<std::size_t>(blocks), 0);
  if (n == 0) return;
  auto id_of = [&](std::size_t i) -> std::int32_t {
    const SphereTreeNode& node = nodes_[i];
    if (node.is_leaf()) return ~node.first;
    return block_of[i] >= 0 ? block_of[i] : ~0;
  };
  root_id_ = id_of(0);
  for (std::size_t i = 0; i < n; ++i) {
    const std::int32_t k = block_of[i];
    if (k < 0) continue;
    const SphereTreeNode& node = nodes_[i];
    float* b = block_bounds_.data() + static_cast<std::size_t>(k) * 4 * w;
    std::uint8_t mask = 0;
    for (std::size_t j = 0; j < w; ++j) {
      if (static_cast<int>(j) < node.count) {
        const std::size_t c = static_cast<std::size_t>(node.first) + j;
        const SphereTreeNode& child = nodes_[c];
        b[j] = child.x;
        b[w + j] = child.y;
        b[2 * w + j] = child.z;
        b[3 * w + j] = child.radius;
        block_child_[static_cast<std::size_t>(k) * w + j] = id_of(c);
        if (child.is_leaf()) mask = static_cast<std::uint8_t>(mask | (1u << j));
      } else {
        b[j] = b[w + j] = b[2 * w + j] = 1e30f;
        b[3 * w + j] = 0.f;
        block_child_[static_cast<std::size_t>(k) * w + j] = ~0;
      }
    }
    block_count_[static_cast<std::size_t>(k)] = static_cast<std::uint8_t>(node.count);
    block_leaf_mask_[static_cast<std::size_t>(k)] = mask;
  }
}

namespace {

// One node's own fields: finite, positive radius and volume, a child count in range.
Status check_node_fields(int i, const SphereTreeNode& node) {
  if (!finite_node(node)) return node_error(i, "non-finite centre, radius or volume");
  if (!(node.radius > 0.f)) return node_error(i, "radius " + std::to_string(node.radius) + " is not positive");
  if (!(node.volume > 0.f)) return node_error(i, "volume " + std::to_string(node.volume) + " is not positive");
  if (node.count < 0 || node.count > kMaxSphereTreeArity)
    return node_error(i, "child count " + std::to_string(node.count) + " outside 0.." + std::to_string(kMaxSphereTreeArity));
  return Ok{};
}

// A leaf node: its leaf sphere exists, is used once, and the node copies it with its volume.
Status check_leaf_node(int i, const SphereTreeNode& node, std::span<const Sphere> leaves, std::vector<char>& leaf_used) {
  const int leaf_total = static_cast<int>(leaves.size());
  if (node.first < 0 || node.first >= leaf_total)
    return node_error(i, "leaf index " + std::to_string(node.first) + " outside 0.." + std::to_string(leaf_total - 1));
  char& used = leaf_used[static_cast<std::size_t>(node.first)];
  if (used) return node_error(i, "leaf index " + std::to_string(node.first) + " used twice");
  used = 1;
  const Sphere& s = leaves[static_cast<std::size_t>(node.first)];
  if (s.x != node.x || s.y != node.y || s.z != node.z || s.radius != node.radius)
    return node_error(i, "leaf node differs from leaf sphere " + std::to_string(node.first));
  const double expected = sphere_volume(static_cast<double>(node.radius));
  if (std::abs(static_cast<double>(node.volume) - expected) > 1e-4 * expected)
    return node_error(i, "leaf volume " + std::to_string(node.volume) + " is not the sphere volume " + std::to_string(expected));
  return Ok{};
}

// An inner node at depth d: its children lie in the array, link back to it, are reached only
// from it (queued at depth d + 1), and their volumes sum to its own.
Status check_children(int i, const SphereTreeNode& node, std::span<const SphereTreeNode> nodes, std::vector<int>& depth_of,
                      std::vector<int>& queue) {
  const int n = static_cast<int>(nodes.size());
  const int d = depth_of[static_cast<std::size_t>(i)];
  if (node.first < 1 || node.first > n - node.count)
    return node_error(i, "children " + std::to_string(node.first) + "+" + std::to_string(node.count) +
                             " outside the node array 1.." + std::to_string(n - 1));
  double child_volume = 0.0;
  for (int c = node.first; c < node.first + node.count; ++c) {
    const SphereTreeNode& child = nodes[static_cast<std::size_t>(c)];
    if (child.parent != i)
      return node_error(c, "parent link " + std::to_string(child.parent) + " but it is a child of node " + std::to_string(i));
    if (depth_of[static_cast<std::size_t>(c)] != 0) return node_error(c, "reached twice (cycle or shared child)");
    depth_of[static_cast<std::size_t>(c)] = d + 1;
    child_volume += static_cast<double>(child.volume);
    queue.push_back(c);
  }
  if (std::abs(child_volume - static_cast<double>(node.volume)) > 1e-4 * child_volume)
    return node_error(i, "volume " + std::to_string(node.volume) + " is not the sum of its children's " + std::to_string(child_volume));
  return Ok{};
}

// Every ancestor encloses every leaf below it (parent chains are known to be acyclic).
Status check_enclosure(std::span<const SphereTreeNode> nodes) {
  const int n = static_cast<int>(nodes.size());
  const double tol = 1e-5 * static_cast<double>(nodes[0].radius);
  for (int i = 0; i < n; ++i) {
    const SphereTreeNode& leaf = nodes[static_cast<std::size_t>(i)];
    if (!leaf.is_leaf()) continue;
    for (int p = leaf.parent; p >= 0; p = nodes[static_cast<std::size_t>(p)].parent) {
      const SphereTreeNode& a = nodes[static_cast<std::size_t>(p)];
      const double dx = static_cast<double>(leaf.x) - static_cast<double>(a.x);
      const double dy = static_cast<double>(leaf.y) - static_cast<double>(a.y);
      const double dz = static_cast<double>(leaf.z) - static_cast<double>(a.z);
      const double reach = std::sqrt(dx * dx + dy * dy + dz * dz) + static_cast<double>(leaf.radius);
      if (reach > static_cast<double>(a.radius) + tol)
        return node_error(p, "does not enclose leaf node " + std::to_string(i) + " (reach " + std::to_string(reach) +
                                 " > radius " + std::to_string(a.radius) + ")");
    }
  }
  return Ok{};
}

}  // namespace

Status validate(const SphereTree& tree) {
  const auto nodes = tree.nodes();
  const auto leaves = tree.leaves();
  if (nodes.empty()) return Error{"sphere tree: no nodes (an empty tree cannot be queried)"};
  const int n = static_cast<int>(nodes.size());
  const int leaf_total = static_cast<int>(leaves.size());
  if (nodes[0].parent != -1) return node_error(0, "the root has parent " + std::to_string(nodes[0].parent) + ", expected -1");

  // reach every node from the root exactly once, checking the links on the way
  std::vector<int> depth_of(static_cast<std::size_t>(n), 0);
  std::vector<char> leaf_used(static_cast<std::size_t>(leaf_total), 0);
  std::vector<int> queue;
  queue.reserve(static_cast<std::size_t>(n));
  queue.push_back(0);
  depth_of[0] = 1;
  int max_depth = 0;
  int leaf_nodes = 0;
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const int i = queue[head];
    const SphereTreeNode& node = nodes[static_cast<std::size_t>(i)];
    max_depth = std::max(max_depth, depth_of[static_cast<std::size_t>(i)]);
    if (auto checked = check_node_fields(i, node); !checked) return checked;
    if (node.is_leaf()) {
      ++leaf_nodes;
      if (auto checked = check_leaf_node(i, node, leaves, leaf_used); !checked) return checked;
    } else if (auto checked = check_children(i, node, nodes, depth_of, queue); !checked) {
      return checked;
    }
  }
  if (static_cast<int>(queue.size()) != n)
    return Error{"sphere tree: " + std::to_string(n - static_cast<int>(queue.size())) + " of " + std::to_string(n) +
                 " nodes are not reachable from the root"};
  if (leaf_nodes != leaf_total)
    return Error{"sphere tree: " + std::to_string(leaf_nodes) + " leaf nodes for " + std::to_string(leaf_total) + " leaf spheres"};
  if (max_depth != tree.depth())
    return Error{"sphere tree: stored depth " + std::to_string(tree.depth()) + " but the longest path has " + std::to_string(max_depth) + " levels"};
  return check_enclosure(nodes);
}

bool SphereTree::refittable() const {
  for (std::size_t i = 0; i < nodes_.size(); ++i)
    if (!nodes_[i].is_leaf() && nodes_[i].first <= static_cast<std::int32_t>(i)) return false;
  return !nodes_.empty();
}

void SphereTree::refit(std::span<const Sphere> leaves) {
  const std::size_t n = std::min(leaves.size(), leaves_.size());
  std::copy_n(leaves.begin(), n, leaves_.begin());
  leaf_parent_volume_ = 0.0;
  // children after parents: a reverse sweep sees every child refitted before its parent
  for (std::size_t i = nodes_.size(); i-- > 0;) {
    SphereTreeNode& node = nodes_[i];
    if (node.is_leaf()) {
      const Sphere& s = leaves_[static_cast<std::size_t>(node.first)];
      node.x = s.x;
      node.y = s.y;
      node.z = s.z;
      node.radius = s.radius;
      node.volume = static_cast<float>(sphere_volume(static_cast<double>(s.radius)));
      continue;
    }
    const auto children = std::span<const SphereTreeNode>(nodes_).subspan(static_cast<std::size_t>(node.first),
                                                                           static_cast<std::size_t>(node.count));
    double volume = 0.0, cx = 0.0, cy = 0.0, cz = 0.0;
    int leaf_children = 0;
    for (const SphereTreeNode& c : children) {
      leaf_children += c.is_leaf() ? 1 : 0;
      const auto v = static_cast<double>(c.volume);
      volume += v;
      cx += v * static_cast<double>(c.x);
      cy += v * static_cast<double>(c.y);
      cz += v * static_cast<double>(c.z);
    }
    // the centre as stored (float), and the radius measured from it, rounded up: the node
    // encloses each child exactly as the queries read them
    node.x = static_cast<float>(cx / volume);
    node.y = static_cast<float>(cy / volume);
    node.z = static_cast<float>(cz / volume);
    double radius = 0.0;
    for (const SphereTreeNode& c : children) {
      const double dx = static_cast<double>(c.x) - static_cast<double>(node.x);
      const double dy = static_cast<double>(c.y) - static_cast<double>(node.y);
      const double dz = static_cast<double>(c.z) - static_cast<double>(node.z);
      radius = std::max(radius, std::sqrt(dx * dx + dy * dy + dz * dz) + static_cast<double>(c.radius));
    }
    node.radius = std::nextafter(static_cast<float>(radius), std::numeric_limits<float>::infinity());
    node.volume = static_cast<float>(volume);
    leaf_parent_volume_ += sphere_volume(static_cast<double>(node.radius)) * static_cast<double>(leaf_children) / node.count;
  }
  const auto w = static_cast<std::size_t>(block_width_);
  std::size_t k = 0;
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    const SphereTreeNode& node = nodes_[i];
    const double ball = sphere_volume(static_cast<double>(node.radius));
    density_[i] = node.is_leaf() || !(ball > 0.0) ? 1.f : static_cast<float>(std::min(1.0, static_cast<double>(node.volume) / ball));
    if (node.is_leaf()) continue;
    float* b = block_bounds_.data() + k * 4 * w;
    for (std::size_t j = 0; j < static_cast<std::size_t>(node.count); ++j) {
      const SphereTreeNode& child = nodes_[static_cast<std::size_t>(node.first) + j];
      b[j] = child.x;
      b[w + j] = child.y;
      b[2 * w + j] = child.z;
      b[3 * w + j] = child.radius;
    }
    ++k;
  }
}

}  // namespace uh::collette
