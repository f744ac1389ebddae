#pragma once
/// \file
/// Top-down construction of a SphereTree from a set of leaf spheres.
///
/// By default (SphereTreeSplit::kBalanced) every leaf ends at the same depth and the inner nodes
/// are as full as the arity allows: a node over m leaves gets as few children as hold them when a
/// child holds at most arity^(h-1) leaves (h: the levels m leaves need), of equal sizes, grouped by
/// recursive bisection along the principal axis of the centres or a fixed direction, whichever
/// gives the halves the smallest enclosing spheres, refined by balanced 2-means. Full nodes fill the
/// volume query's SIMD blocks, and leaves at one depth mean that the simultaneous descent never
/// meets a leaf against an inner node: on the query benchmark's deep random poses this visits
/// 4,388 node pairs where the k-means tree visits 7,256, for the same pairs (docs/benchmarks.md).
/// SphereTreeSplit::kKMeans splits each node's leaves into up to `arity` clusters by k-means on the
/// sphere centres, weighted by sphere volume (a deterministic stand-in for the batch neural gas of
/// the original IST), seeded by volume quantiles along the longest axis: tighter spheres, unevenly
/// filled nodes, leaves at several depths. Either way each inner node gets a tight enclosing sphere
/// of all leaf spheres below it (iterative farthest-point refinement, then rounded outwards so that
/// the float sphere encloses). Deterministic: the same input gives the same tree bit for bit.

#include <span>

#include "uh/collette/sphere_tree.hpp"
#include "uh/core/contact.hpp"
#include "uh/core/result.hpp"

namespace uh::collette {

/// Changes whenever build_sphere_tree()'s default output changes (2: balanced trees; 3: their cuts
/// chosen by enclosing spheres and refined by 2-means), so that caches of built trees can be keyed
/// by it and rebuilt.
inline constexpr int kSphereTreeBuilderVersion = 3;

/// How build_sphere_tree() divides a node's leaves among its children.
enum class SphereTreeSplit {
  kBalanced,  ///< leaves at one depth, full nodes (recursive bisection)
  kKMeans,    ///< up to `arity` volume-weighted k-means clusters per node
};

/// Options for build_sphere_tree().
struct SphereTreeBuildOptions {
  int arity = 8;                ///< children per inner node, 2..kMaxSphereTreeArity (8 measured fastest)
  SphereTreeSplit split = SphereTreeSplit::kBalanced;
  int kmeans_iterations = 30;    ///< most Lloyd iterations per split (kKMeans; stops early when stable)
  int enclosing_iterations = 48; ///< refinement steps of each enclosing sphere
};

/// Builds the hierarchy over `leaves` (mesh frame; non-overlapping in an IST, though the builder
/// does not require it). Fails with a message for an empty set, a bad option or a leaf with a
/// non-finite centre or a radius that is not positive and finite.
/// Not real-time safe; any thread. About 0.18 s for 10,000 leaves (k-means: 0.03 s).
Result<SphereTree> build_sphere_tree(std::span<const Sphere> leaves, const SphereTreeBuildOptions& options = {});

/// Regroups `tree`'s hierarchy over its leaves where they are now (as the last
/// SphereTree::refit() left them): the same leaves in the same order (a leaf node still names its
/// leaf by index), new inner nodes, exactly as build_sphere_tree() would build them over those
/// leaves, with the densities and traversal blocks. The result is refittable(). For a deformable
/// object whose refitted tree has grown loose. The tree's arrays keep their storage when the node
/// count stays (the balanced split's count depends on the leaf count and arity alone); the
/// grouping's own scratch is allocated. Fails as build_sphere_tree() does (the tree is unchanged).
/// Not real-time safe; the thread that owns the tree. Costs what build_sphere_tree() does.
Status rebuild_sphere_tree(SphereTree& tree, const SphereTreeBuildOptions& options = {});

}  // namespace uh::collette
