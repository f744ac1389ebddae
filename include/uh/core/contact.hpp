#pragma once
/// \file
/// Plain-data collision results shared between modules (after MuJoCo's mjContact).
///
/// Collette writes these; ForceComp reads them without knowing how they were found. They are
/// trivially copyable, have a fixed capacity plus a count, and use integer ids, never pointers,
/// so that a whole frame can cross threads through a LatestValue handoff.

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "uh/core/math.hpp"

namespace uh {

/// A sphere in some body frame (the field holding it names the frame).
struct Sphere {
  float x = 0.f;  ///< centre [length unit of the mesh]
  float y = 0.f;
  float z = 0.f;
  float radius = 0.f;  ///< radius [length unit], > 0 for a real sphere
};

/// One overlapping pair of leaf spheres, sphere a of object A and sphere b of object B.
struct SpherePairContact {
  float volume = 0.f;             ///< lens volume [length^3], >= 0
  float area = 0.f;               ///< pi a^2 of the intersection disk [length^2] = -dV/d(distance)
  float normal_world[3] = {};     ///< unit, world frame, from a's centre towards b's centre: pushes B out of A
  float centroid_world[3] = {};   ///< lens centroid, world frame [length]; on the centre line
  Sphere sphere_a_local{};        ///< a in A's body (mesh) frame
  Sphere sphere_b_local{};        ///< b in B's body (mesh) frame
  std::int32_t leaf_a = -1;       ///< index of a among A's leaves
  std::int32_t leaf_b = -1;       ///< index of b among B's leaves
};
static_assert(std::is_trivially_copyable_v<SpherePairContact>);

/// Everything one collision query between two objects found, at the poses it used.
/// `kMaxPairs` bounds the pair list; when more pairs overlap, `truncated` is set, the totals
/// still cover all pairs and `pairs` holds the first kMaxPairs found.
struct ContactFrame {
  static constexpr int kMaxPairs = 32768;

  std::uint64_t sequence = 0;       ///< increases by one per published frame of this watcher
  double time_s = 0.0;              ///< steady-clock time the query started [s]
  std::int32_t object_a = -1;       ///< id of A in the collision world
  std::int32_t object_b = -1;       ///< id of B in the collision world
  Pose world_from_a{};              ///< pose of A used by the query
  Pose world_from_b{};              ///< pose of B used by the query
  double total_volume = 0.0;        ///< sum of all pair volumes [length^3], >= 0
  Vec3 restoring_direction_world{}; ///< unit direction of sum(volume * normal): pushes B out of A; zero if none
  Vec3 volume_centroid_world{};     ///< volume-weighted mean of the lens centroids [length]
  /// d(total_volume)/d(position of B), world frame [length^2]: -sum(area * normal) over the pairs
  /// (area = pi a^2 of a pair's intersection disk). Its negation is the exact restoring direction
  /// of the packings, closer to the meshes' true one than restoring_direction_world, and the
  /// direction of the gradient force law (forcecomp/penalty_force.hpp).
  Vec3 volume_gradient_world{};
  double distance = 0.0;            ///< separation when apart (upper bound), 0 when touching [length]
  double query_seconds = 0.0;       ///< time the query took [s]
  std::int32_t pair_count = 0;      ///< number of valid entries in pairs
  bool truncated = false;           ///< more pairs overlapped than kMaxPairs
  std::array<SpherePairContact, kMaxPairs> pairs{};
};
static_assert(std::is_trivially_copyable_v<ContactFrame>);

/// Copies `src` into `dst`, only the `pair_count` valid pairs (a full ContactFrame is ~2.4 MB;
/// a frame usually holds a few thousand pairs). Real-time safe.
inline void copy_contact_frame(const ContactFrame& src, ContactFrame& dst) {
  const auto count = static_cast<std::size_t>(src.pair_count < 0 ? 0 : src.pair_count);
  dst.sequence = src.sequence;
  dst.time_s = src.time_s;
  dst.object_a = src.object_a;
  dst.object_b = src.object_b;
  dst.world_from_a = src.world_from_a;
  dst.world_from_b = src.world_from_b;
  dst.total_volume = src.total_volume;
  dst.restoring_direction_world = src.restoring_direction_world;
  dst.volume_centroid_world = src.volume_centroid_world;
  dst.volume_gradient_world = src.volume_gradient_world;
  dst.distance = src.distance;
  dst.query_seconds = src.query_seconds;
  dst.pair_count = src.pair_count;
  dst.truncated = src.truncated;
  std::copy_n(src.pairs.begin(), count < src.pairs.size() ? count : src.pairs.size(), dst.pairs.begin());
}

}  // namespace uh
