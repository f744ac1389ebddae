#pragma once
/// \file
/// Plain-data collision results shared between modules (after MuJoCo's mjContact).
///
/// Collette writes these; ForceComp reads them without knowing how they were found. They
/// use integer ids, never pointers; a frame's pair list is sized by what overlaps and crosses
/// threads in place through a LatestValue handoff (ContactFrame).

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
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

/// One object pair's part of a ContactFrame: the pair, the poses its query used, its totals and
/// its run of the frame's pairs. A frame of a watched pair has one section while the pair has
/// pairs; a frame of a tool watched against everything has one per object the tool touches.
struct ContactSection {
  std::int32_t object_a = -1;    ///< id of A in the collision world
  std::int32_t object_b = -1;    ///< id of B (the tool of a tool watcher)
  Pose world_from_a{};           ///< pose of A used by the query
  Pose world_from_b{};           ///< pose of B used by the query
  double total_volume = 0.0;     ///< sum of this section's pair volumes [length^3]
  Vec3 volume_gradient_world{};  ///< d(total_volume)/d(position of B) [length^2]
  /// c_A c_B, the product of the two packings' coverages (by which the gradient law is calibrated;
  /// 1 when the objects were registered without one)
  double coverage_product = 1.0;
  std::int32_t first_pair = 0;  ///< index of this section's first pair in ContactFrame::pairs()
  std::int32_t pair_count = 0;  ///< pairs of this section
  bool truncated = false;       ///< the query found more pairs than it could store (totals cover all)
};
static_assert(std::is_trivially_copyable_v<ContactSection>);

/// Everything one collision step found for one watcher, at the poses it used.
///
/// The pair list is sized by what overlaps: the frame owns growable storage that only the writer
/// enlarges (reserve_pairs(), outside any real-time path); a frame never holds a fixed maximum.
/// A frame is move-only; it crosses threads in place, through a LatestValue<ContactFrame> whose
/// reader evaluates the pairs where they lie (CollisionWorld::take_contact). copy_contact_frame()
/// copies one where a copy is really needed.
///
/// The header fields describe the whole frame: for a watched pair, that pair; for a tool watched
/// against everything, `object_a` is kEveryObject and the totals sum all sections.
struct ContactFrame {
  static constexpr std::int32_t kEveryObject = -2;  ///< object_a of a tool-against-everything frame

  std::uint64_t sequence = 0;       ///< increases by one per published frame of this watcher
  double time_s = 0.0;              ///< steady-clock time the query started [s]
  std::int32_t object_a = -1;       ///< id of A in the collision world (kEveryObject: see sections)
  std::int32_t object_b = -1;       ///< id of B in the collision world
  Pose world_from_a{};              ///< pose of A used by the query (identity for kEveryObject)
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
  double query_seconds = 0.0;       ///< time the queries took [s]
  std::int32_t pair_count = 0;      ///< number of valid entries in pairs()
  bool truncated = false;           ///< a query found more pairs than it could store (totals cover all)

  ContactFrame() = default;
  ContactFrame(const ContactFrame&) = delete;
  ContactFrame& operator=(const ContactFrame&) = delete;
  ContactFrame(ContactFrame&&) noexcept = default;
  ContactFrame& operator=(ContactFrame&&) noexcept = default;

  /// The valid pairs (pair_count of them).
  std::span<const SpherePairContact> pairs() const {
    return {pair_storage_.get(), valid(pair_count, pair_capacity_)};
  }
  std::span<SpherePairContact> pairs() { return {pair_storage_.get(), valid(pair_count, pair_capacity_)}; }
  /// The sections (see ContactSection), section_count of them.
  std::span<const ContactSection> sections() const {
    return {section_storage_.get(), valid(section_count, section_capacity_)};
  }
  std::span<ContactSection> sections() {
    return {section_storage_.get(), valid(section_count, section_capacity_)};
  }
  std::int32_t section_count = 0;  ///< number of valid entries in sections()

  /// Makes room for `pairs` pairs, keeping the valid ones. Allocates when the storage is smaller
  /// (writer thread, outside real-time paths); never shrinks.
  void reserve_pairs(std::int32_t pairs) {
    if (pairs <= pair_capacity_) return;
    const std::int32_t capacity = std::max(pairs, pair_capacity_ + pair_capacity_ / 2);
    auto grown = std::make_unique<SpherePairContact[]>(static_cast<std::size_t>(capacity));
    std::copy_n(pair_storage_.get(), valid(pair_count, pair_capacity_), grown.get());
    pair_storage_ = std::move(grown);
    pair_capacity_ = capacity;
  }
  /// Releases the pair storage when it is more than four times what `pairs` needs (a deep contact
  /// that ended), so that memory follows what overlaps. Writer thread; allocates when it shrinks.
  void trim_pairs(std::int32_t pairs) {
    if (pair_capacity_ <= 1024 || pair_capacity_ / 4 <= pairs) return;
    const std::int32_t capacity = std::max<std::int32_t>(pairs * 2, 1024);
    auto kept = std::make_unique<SpherePairContact[]>(static_cast<std::size_t>(capacity));
    std::copy_n(pair_storage_.get(),
                std::min(valid(pair_count, pair_capacity_), static_cast<std::size_t>(capacity)), kept.get());
    pair_storage_ = std::move(kept);
    pair_capacity_ = capacity;
  }
  /// Sets pair_count to `pairs`, growing the storage first if needed (new pairs value-initialised).
  void resize_pairs(std::int32_t pairs) {
    reserve_pairs(pairs);
    pair_count = std::max(pairs, 0);
  }
  /// Appends a section, growing the storage if needed (writer thread).
  ContactSection& add_section(const ContactSection& section) {
    if (section_count >= section_capacity_) {
      const std::int32_t capacity = std::max(4, 2 * section_capacity_);
      auto grown = std::make_unique<ContactSection[]>(static_cast<std::size_t>(capacity));
      std::copy_n(section_storage_.get(), valid(section_count, section_capacity_), grown.get());
      section_storage_ = std::move(grown);
      section_capacity_ = capacity;
    }
    ContactSection& s = section_storage_[static_cast<std::size_t>(section_count++)];
    s = section;
    return s;
  }
  std::int32_t pair_capacity() const { return pair_capacity_; }
  /// Heap bytes this frame owns (pairs and sections).
  std::size_t memory_bytes() const {
    return static_cast<std::size_t>(pair_capacity_) * sizeof(SpherePairContact) +
           static_cast<std::size_t>(section_capacity_) * sizeof(ContactSection);
  }

 private:
  static std::size_t valid(std::int32_t count, std::int32_t capacity) {
    return static_cast<std::size_t>(std::clamp(count, 0, capacity));
  }
  std::unique_ptr<SpherePairContact[]> pair_storage_;
  std::int32_t pair_capacity_ = 0;
  std::unique_ptr<ContactSection[]> section_storage_;
  std::int32_t section_capacity_ = 0;
};

/// Copies `src` into `dst`: the header, the valid pairs and the sections. Real-time safe when
/// `dst` has room for src's pairs and sections already; otherwise it allocates.
inline void copy_contact_frame(const ContactFrame& src, ContactFrame& dst) {
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
  dst.truncated = src.truncated;
  const auto pairs = src.pairs();
  dst.resize_pairs(static_cast<std::int32_t>(pairs.size()));
  std::copy(pairs.begin(), pairs.end(), dst.pairs().begin());
  dst.section_count = 0;
  for (const ContactSection& s : src.sections()) dst.add_section(s);
}

}  // namespace uh
