#pragma once
/// \file
/// SphereTree: an Inner Sphere Tree, the immutable n-ary bounding-sphere hierarchy over the
/// non-overlapping leaf spheres that fill an object (after Weller & Zachmann's IST, laid out like
/// madmann91/bvh v2: flat node array, int32 indices, contiguous children).
///
/// Built by build_sphere_tree() (sphere_tree_builder.hpp) or loaded from a .ist file
/// (ist_file.hpp). Once built it never changes: share it read-only between any number of threads;
/// the per-thread scratch lives in the query objects (volume_query.hpp, ...). A deformable
/// object's own copies are the exception: refit() and rebuild_sphere_tree() change them.

#include <cstdint>
#include <span>
#include <vector>

#include "uh/core/contact.hpp"
#include "uh/core/result.hpp"

namespace uh::collette {

struct SphereTreeBuildOptions;
class SphereTree;
Status rebuild_sphere_tree(SphereTree& tree, const SphereTreeBuildOptions& options);

/// One node of a SphereTree: 32 bytes, so that two nodes share a cache line and a 4-child block
/// is two lines. Frame and length unit: those of the object's mesh.
struct SphereTreeNode {
  float x = 0.f;       ///< centre of the node's sphere [length]
  float y = 0.f;
  float z = 0.f;
  float radius = 0.f;  ///< inner node: encloses every leaf sphere below; leaf: the leaf sphere [length]
  float volume = 0.f;  ///< total volume of the leaf spheres at or below this node [length^3]
  std::int32_t first = 0;   ///< inner node: index of the first child; leaf: index into SphereTree::leaves()
  std::int32_t count = 0;   ///< inner node: number of children (contiguous from `first`), >= 1; leaf: 0
  std::int32_t parent = -1; ///< index of the parent node; -1 for the root (node 0)

  constexpr bool is_leaf() const { return count == 0; }
};
static_assert(sizeof(SphereTreeNode) == 32);

/// The most children an inner node may have (builder arity and file loader limit).
inline constexpr int kMaxSphereTreeArity = 8;

/// An immutable Inner Sphere Tree. Node 0 is the root. Owns its arrays.
/// Thread rules: all member functions are const and may be called from any thread concurrently.
class SphereTree {
 public:
  SphereTree() = default;
  /// Takes the arrays as they are; call validate() on data from outside (files, tests).
  SphereTree(std::vector<SphereTreeNode> nodes, std::vector<Sphere> leaves, int depth, int arity);

  std::span<const SphereTreeNode> nodes() const { return nodes_; }
  /// The leaf spheres in their original (packing) order; leaf nodes refer to them by index.
  std::span<const Sphere> leaves() const { return leaves_; }
  const SphereTreeNode& root() const { return nodes_.front(); }
  bool empty() const { return nodes_.empty(); }
  int node_count() const { return static_cast<int>(nodes_.size()); }
  int leaf_count() const { return static_cast<int>(leaves_.size()); }
  /// Number of node levels on the longest root-to-leaf path (a single leaf: 1).
  int depth() const { return depth_; }
  /// The largest number of children the builder allowed per node.
  int arity() const { return arity_; }
  /// Sum of the leaf sphere volumes [length^3].
  double total_volume() const { return nodes_.empty() ? 0.0 : static_cast<double>(nodes_.front().volume); }
  /// Sum of the sphere volumes of the inner nodes just above the leaves [length^3] (each inner
  /// node counted by the share of its children that are leaves: in a balanced tree, the lowest
  /// inner level). A refit loosens it as the leaves move apart from their first grouping, and a
  /// rebuild over the moved leaves tightens it again; the levels above are left out because an
  /// elongated shape keeps them loose however they are grouped. A deformable object compares it
  /// with its own volume to tell when to rebuild (docs/deformables.md). Kept by the constructor
  /// and refit().
  double leaf_parent_volume() const { return leaf_parent_volume_; }

  /// Derived, traversal-friendly copy of the hierarchy used by the queries (built by the
  /// constructor; read-only). Every inner node owns one "block" holding its children's spheres as
  /// structure of arrays, `width` lanes each (4 for arity <= 4, else 8): one or two cache lines
  /// per node visit. A child is named by a traversal id: >= 0 the block of an inner child,
  /// < 0 a leaf child, ~id being its index into leaves(). Unused lanes hold a far-away centre
  /// (1e30) and radius 0 so that they never overlap anything finite.
  struct Blocks {
    const float* bounds = nullptr;          ///< block k: x[width], y[width], z[width], r[width]
    const std::int32_t* child = nullptr;    ///< block k: traversal ids of its children [width]
    const std::uint8_t* count = nullptr;    ///< block k: number of children
    const std::uint8_t* leaf_mask = nullptr;///< block k: bit j set when child j is a leaf
    int width = 4;
    std::int32_t root = 0;                  ///< traversal id of the root
    std::int32_t size = 0;                  ///< number of blocks (inner nodes)
  };
  /// Packing density of each node: leaf volume below / volume of its sphere, in (0, 1]; 1 for a
  /// leaf. Derived by the constructor for the time-critical query's expected overlaps.
  std::span<const float> density() const { return density_; }

  /// Whether refit() may run on this tree: every inner node's children come after it in the node
  /// array (as build_sphere_tree() lays them out), so a reverse sweep is bottom-up. Setup only.
  bool refittable() const;

  /// The one change a tree allows, for a deformable object's own copies of its tree (uh::soft: a
  /// copy per slot of a triple buffer, refitted by the simulation thread before it is published;
  /// never a tree other threads read meanwhile): moves the leaf spheres to `leaves` (one per leaf,
  /// packing order, positive radii) and refits every inner node bottom-up to enclose its
  /// children (centre: their volume-weighted centroid), with volumes, densities and the
  /// traversal blocks. The topology stays (rebuild_sphere_tree() regroups the leaves where they
  /// are). Needs refittable(). Real-time safe: no allocation.
  void refit(std::span<const Sphere> leaves);

  Blocks blocks() const {
    return {block_bounds_.data(), block_child_.data(), block_count_.data(), block_leaf_mask_.data(), block_width_, root_id_,
            static_cast<std::int32_t>(block_count_.size())};
  }

 private:
  friend Status rebuild_sphere_tree(SphereTree& tree, const SphereTreeBuildOptions& options);
  // the densities, leaf_parent_volume() and the traversal blocks, from the nodes (their arrays
  // keep their storage when the sizes stay)
  void derive();
  // the share of node i's children that are leaves (0 for a leaf or a malformed range)
  double leaf_share(std::size_t i) const;

  std::vector<float> block_bounds_;
  std::vector<std::int32_t> block_child_;
  std::vector<std::uint8_t> block_count_;
  std::vector<std::uint8_t> block_leaf_mask_;
  std::vector<float> density_;
  int block_width_ = 4;
  std::int32_t root_id_ = 0;
  std::vector<SphereTreeNode> nodes_;
  std::vector<Sphere> leaves_;
  int depth_ = 0;
  int arity_ = 0;
  double leaf_parent_volume_ = 0.0;
};

/// Checks every invariant of `tree`: non-empty; children contiguous, in range and at most
/// kMaxSphereTreeArity per node; every node reached exactly once from the root (no cycles, no
/// sharing) with matching parent links; each leaf index used exactly once and the leaf node equal
/// to its leaf sphere; finite values and positive radii; each inner node enclosing every leaf sphere
/// below it (relative tolerance 1e-5 of the root radius); volumes summing up (relative 1e-4);
/// the stored depth. The error message names the first broken invariant and node.
/// Not real-time safe (allocates); any thread.
Status validate(const SphereTree& tree);

}  // namespace uh::collette
