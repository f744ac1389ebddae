#pragma once
/// \file
/// Filling a closed mesh with non-overlapping spheres: the leaves of an Inner Sphere Tree.

#include <cstdint>
#include <functional>
#include <vector>

#include "uh/collette/triangle_mesh.hpp"
#include "uh/core/contact.hpp"
#include "uh/core/result.hpp"

namespace uh::collette {

/// Settings for pack_spheres() (Box2D-style aggregate; use designated initialisers).
struct PackingOptions {
  /// Stop after this many spheres (0 = no limit: stop when no free voxel is left).
  std::int64_t target_sphere_count = 10000;
  /// Edge of the distance-field voxels [length unit of the mesh]; 0 = chosen from the target
  /// count and the mesh volume (smaller voxels: better coverage, slower, more memory).
  double voxel_size = 0.0;
  /// Spheres stop this fraction of the voxel size short of the surface and of each other, so
  /// they stay strictly inside and disjoint after rounding to float.
  double safety_margin = 1e-3;
  /// Move each chosen centre continuously to grow its radius beyond what the grid allows.
  bool refine_centres = true;
  /// Largest sphere radius [length unit of the mesh]; 0 = unbounded. Bounded, the packing is as
  /// full under its faces as it is on average, so a pressed face feels the stiffness the law
  /// is calibrated for (docs/collette-packing.md, "Bounded radius"); unbounded, a thick object
  /// gets a few large spheres inside and a thinner fill under its faces.
  double max_radius = 0.0;
  /// Surface points sampled per triangle (besides the vertices) to measure max_gap; 0 = only vertices.
  int gap_samples_per_triangle = 1;
  /// Called from the calling thread with a fraction in [0, 1] that never decreases and ends at 1.
  std::function<void(double fraction)> progress{};
};

/// Quality and cost figures of one packing (plain, trivially copyable).
struct PackingReport {
  std::int64_t sphere_count = 0;
  double mesh_volume = 0.0;     ///< [length^3]
  double sphere_volume = 0.0;   ///< sum of sphere volumes [length^3] (they do not overlap)
  double coverage = 0.0;        ///< sphere_volume / mesh_volume, in [0, 1)
  double max_gap = 0.0;         ///< largest distance from a sampled surface point to the union of
                                ///< spheres [length]: the dead zone before forces start
  double build_seconds = 0.0;   ///< wall time of pack_spheres() [s]
  double voxel_size = 0.0;      ///< voxel edge actually used [length]
  std::int64_t voxel_count = 0; ///< interior voxels of the distance field
  double min_radius = 0.0;      ///< smallest sphere radius [length]
  double max_radius = 0.0;      ///< largest sphere radius [length]
};

/// The spheres (mesh frame and units, largest first) and the report.
struct SpherePacking {
  std::vector<Sphere> spheres;
  PackingReport report{};
};

/// Fills a closed (validated) mesh with non-overlapping spheres strictly inside it: greedy
/// largest-free-sphere placement on a voxel distance field, with exact distance checks.
/// Deterministic: the same mesh and options give bit-identical spheres. Errors for an empty or
/// open mesh or options that would need too much memory. Setup code: allocates, may take seconds;
/// any thread (one call per thread); not real-time safe.
Result<SpherePacking> pack_spheres(const TriangleMesh& mesh, const PackingOptions& options = {});

/// Largest distance from the sampled surface points (all vertices plus `samples_per_triangle`
/// deterministic points per triangle) to the union of the spheres [length]. Brute force would be
/// O(points * spheres); this uses a grid. Not real-time safe.
double measure_max_gap(const TriangleMesh& mesh, const std::vector<Sphere>& spheres, int samples_per_triangle = 1);

}  // namespace uh::collette
