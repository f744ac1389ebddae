#pragma once
/// \file
/// HeldContactSet: multi-rate force rendering by re-evaluating the last collision result at the
/// current poses every haptic tick.

#include <cstdint>
#include <memory>
#include <span>

#include "uh/core/contact.hpp"
#include "uh/core/math.hpp"
#include "uh/forcecomp/penalty_force.hpp"

namespace uh::forcecomp {

/// Keeps the last overlapping leaf-sphere pairs (spheres in their body frames) and recomputes
/// their lens volumes, normals and centroids for new poses of A and B.
///
/// Why: the collision thread (a sphere-tree traversal) runs at 200-1000 Hz, slower than the
/// haptic thread under deep interpenetration. Holding the last force would make it step at every
/// new collision result; re-evaluating the held pairs makes it follow the hand smoothly (cost
/// O(pairs), no traversal). Limits: pairs that start to overlap after the held query are missed
/// until the next collision result arrives; pairs that stop overlapping drop out (volume 0).
///
/// Threads: one owner thread (the haptic thread) calls hold() and reevaluate(); the frames it
/// holds arrive through a core handoff (LatestValue). Memory: the capacity is allocated by the
/// constructor; hold() and reevaluate() never allocate, lock, throw or log (real-time safe).
class HeldContactSet {
 public:
  /// Allocates room for `capacity` pairs (> 0). Not real-time safe.
  explicit HeldContactSet(std::int32_t capacity = ContactFrame::kMaxPairs);

  /// Replaces the held pairs with the frame's pairs, remembering the frame's sequence and time.
  /// Pairs beyond the capacity are dropped and counted in dropped_pairs(). Real-time safe.
  void hold(const ContactFrame& frame);
  /// Same from a bare pair list: `time_s` is when the pairs were computed [s].
  void hold(std::span<const SpherePairContact> pairs, std::uint64_t sequence, double time_s);
  /// Forgets all pairs (e.g. when the objects separated). Real-time safe.
  void clear();

  /// Recomputes every held pair at the poses world_from_a, world_from_b: lens volume (0 when the
  /// spheres no longer overlap), normal from a's centre towards b's centre, lens centroid, all in
  /// the world frame. When the centres coincide the normal held from the query (rotated with A)
  /// is kept. Returns a view of the preallocated scratch, valid until the next call. Real-time safe.
  std::span<const SpherePairContact> reevaluate(const Pose& world_from_a, const Pose& world_from_b);

  /// Re-evaluates the held pairs at the poses world_from_a, world_from_b and applies the penalty
  /// law (penalty_force.hpp) in the same pass: equal, up to rounding, to
  /// evaluate_penalty(reevaluate(world_from_a, world_from_b), input), but faster (about 1.3x in
  /// uh_forcecomp_bench) because it works in A's frame (one rotation per pair) on compact scratch
  /// and keeps doubles throughout. The result is in the world frame. Real-time safe.
  PenaltyResult evaluate(const Pose& world_from_a, const Pose& world_from_b, const PenaltyInput& input);

  std::int32_t size() const { return size_; }
  std::int32_t capacity() const { return capacity_; }
  bool empty() const { return size_ == 0; }
  /// Sequence number of the held frame (0 if none was held).
  std::uint64_t sequence() const { return sequence_; }
  /// Time the held pairs were computed [s] (the frame's time_s); the watchdog uses its age.
  double time_s() const { return time_s_; }
  /// Pairs that did not fit in the capacity since construction (a warning counter).
  std::uint64_t dropped_pairs() const { return dropped_pairs_; }

 private:
  std::int32_t capacity_ = 0;
  std::int32_t size_ = 0;
  std::uint64_t sequence_ = 0;
  double time_s_ = 0.0;
  std::uint64_t dropped_pairs_ = 0;
  std::unique_ptr<SpherePairContact[]> held_;   // pairs as held (sphere locals are what matters)
  std::unique_ptr<Vec3[]> normal_a_local_;      // held normals in A's frame, for coincident centres
  std::unique_ptr<SpherePairContact[]> scratch_;  // output of reevaluate()
  // the two spheres of a held pair packed for evaluate(): 32 bytes, one cache line per two pairs
  struct PackedPair {
    float ax, ay, az, ar;  // a in A's frame
    float bx, by, bz, br;  // b in B's frame
  };
  std::unique_ptr<PackedPair[]> packed_;
  struct LocalPair {
    float volume;
    float area;        // pi a^2 of the intersection disk
    float nx, ny, nz;  // unit normal, A's frame, from a towards b
    float cx, cy, cz;  // lens centroid, A's frame
  };
  std::unique_ptr<LocalPair[]> local_;  // scratch of evaluate(): the overlapping pairs only
  std::int32_t local_count_ = 0;
};

}  // namespace uh::forcecomp
