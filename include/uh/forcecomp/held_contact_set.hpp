#pragma once
/// \file
/// HeldContactSet: multi-rate force rendering by re-evaluating the last collision result at the
/// current poses every haptic tick.

#include <cstdint>
#include <memory>
#include <span>

#include "uh/core/contact.hpp"
#include "uh/core/math.hpp"
#include "uh/forcecomp/contact_patches.hpp"
#include "uh/forcecomp/penalty_force.hpp"

namespace uh::forcecomp {

/// Holds the last overlapping leaf-sphere pairs (spheres in their body frames) and recomputes
/// their lens volumes, normals and centroids for new poses of A and B.
///
/// Why: the collision thread (a sphere-tree traversal) runs at 200-1000 Hz, slower than the
/// haptic thread under deep interpenetration. Holding the last force would make it step at every
/// new collision result; re-evaluating the held pairs makes it follow the hand smoothly (cost
/// O(pairs), no traversal). Limits: pairs that start to overlap after the held query are missed
/// until the next collision result arrives; pairs that stop overlapping drop out (volume 0).
///
/// The set is a view: hold() keeps a reference to the pairs where they lie (a ContactFrame the
/// haptic thread took from the collision world's handoff), never a copy, so its memory does not
/// depend on how many pairs overlap. The held pairs must stay valid and unchanged until the next
/// hold() or clear(): the frame's reader keeps its slot until it takes the next frame.
///
/// Threads: one owner thread (the haptic thread) calls hold() and evaluate(). Memory: only
/// reevaluate() (the per-pair reference) needs scratch, `reevaluate_capacity` pairs allocated by
/// the constructor; hold(), evaluate() and reevaluate() never allocate, lock, throw or log
/// (real-time safe).
class HeldContactSet {
 public:
  /// Room for reevaluate() to return up to `reevaluate_capacity` pairs (>= 0). Not real-time safe.
  explicit HeldContactSet(std::int32_t reevaluate_capacity = 0);

  /// Holds all pairs of the frame (whatever its sections), remembering its sequence and time and,
  /// for coincident centres, A's orientation (one A: the frame's pair or its first section).
  void hold(const ContactFrame& frame);
  /// Holds one section of a frame (its pairs and A's pose).
  void hold(const ContactFrame& frame, const ContactSection& section);
  /// Same from a bare pair list: `time_s` is when the pairs were computed [s]. A's orientation is
  /// taken as the identity for the coincident-centre normals.
  void hold(std::span<const SpherePairContact> pairs, std::uint64_t sequence, double time_s);
  /// Forgets all pairs (e.g. when the objects separated). Real-time safe.
  void clear();

  /// Recomputes every held pair at the poses world_from_a, world_from_b: lens volume (0 when the
  /// spheres no longer overlap), normal from a's centre towards b's centre, lens centroid, all in
  /// the world frame. When the centres coincide the normal held from the query (rotated with A)
  /// is kept. Returns a view of the preallocated scratch, valid until the next call; pairs beyond
  /// the scratch's capacity are left out and counted in dropped_pairs(). Real-time safe.
  std::span<const SpherePairContact> reevaluate(const Pose& world_from_a, const Pose& world_from_b);

  /// Re-evaluates the held pairs at the poses world_from_a, world_from_b and applies the penalty
  /// law (penalty_force.hpp): equal, up to rounding, to
  /// evaluate_penalty(reevaluate(world_from_a, world_from_b), input), without scratch: it works in
  /// A's frame (one rotation per pair), per pair in float, sums in double, in two passes over the
  /// held pairs (the total volume, which scales the damping, then the forces). The result is in
  /// the world frame. With a patch `selection`, the force of that patch's pairs only, their
  /// damping scaled by the volume of all held pairs (so that the patches' forces sum to the
  /// whole's; its total_volume stays the whole's). Real-time safe.
  PenaltyResult evaluate(const Pose& world_from_a, const Pose& world_from_b, const PenaltyInput& input,
                         const PatchSelection& selection = {});

  std::int32_t size() const { return static_cast<std::int32_t>(held_.size()); }
  bool empty() const { return held_.empty(); }
  /// Sequence number of the held frame (0 if none was held).
  std::uint64_t sequence() const { return sequence_; }
  /// Time the held pairs were computed [s] (the frame's time_s); the watchdog uses its age.
  double time_s() const { return time_s_; }
  /// Pairs reevaluate() left out for want of scratch since construction (a warning counter).
  std::uint64_t dropped_pairs() const { return dropped_pairs_; }

 private:
  // a pair's held normal in A's frame (the normal of coincident centres)
  Vec3 held_normal_in_a(const SpherePairContact& p) const {
    return rotate(a_from_world_held_,
                  Vec3{static_cast<double>(p.normal_world[0]), static_cast<double>(p.normal_world[1]),
                       static_cast<double>(p.normal_world[2])});
  }

  std::span<const SpherePairContact> held_;
  Quat a_from_world_held_{};  // A's orientation at the held query, inverted: normals into A's frame
  std::uint64_t sequence_ = 0;
  double time_s_ = 0.0;
  std::uint64_t dropped_pairs_ = 0;
  std::int32_t scratch_capacity_ = 0;
  std::unique_ptr<SpherePairContact[]> scratch_;  // output of reevaluate()
};

}  // namespace uh::forcecomp
