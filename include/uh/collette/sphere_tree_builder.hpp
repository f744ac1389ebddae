#pragma once
/// \file
/// Top-down construction of a SphereTree from a set of leaf spheres.
///
/// Each node's leaves are split into up to `arity` clusters by k-means on the sphere centres,
/// weighted by sphere volume (a deterministic stand-in for the batch neural gas of the original
/// IST), seeded by volume quantiles along the longest axis. Each inner node gets a tight enclosing
/// sphere of all leaf spheres below it (iterative farthest-point refinement, then rounded outwards
/// so that the float sphere encloses). Deterministic: the same input gives the same tree bit for bit.

#include <span>

#include "uh/collette/sphere_tree.hpp"
#include "uh/core/contact.hpp"
#include "uh/core/result.hpp"

namespace uh::collette {

/// Options for build_sphere_tree().
struct SphereTreeBuildOptions {
  int arity = 8;                ///< children per inner node, 2..kMaxSphereTreeArity (8 measured fastest)
  int kmeans_iterations = 30;   ///< most Lloyd iterations per split (stops early when stable)
  int enclosing_iterations = 48; ///< refinement steps of each enclosing sphere
};

/// Builds the hierarchy over `leaves` (mesh frame; non-overlapping in an IST, though the builder
/// does not require it). Fails with a message for an empty set, a bad option or a leaf with a
/// non-finite centre or a radius that is not positive and finite.
/// Not real-time safe; any thread. About 10 ms for 10,000 leaves.
Result<SphereTree> build_sphere_tree(std::span<const Sphere> leaves, const SphereTreeBuildOptions& options = {});

}  // namespace uh::collette
