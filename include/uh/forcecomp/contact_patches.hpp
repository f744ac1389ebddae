#pragma once
/// \file
/// Contact patches: the connected regions of one (object, tool) overlap, so that friction has a
/// stick point and a normal force per region (docs/forcecomp.md, "Materials").
///
/// Why: a tool pinched between two faces of one object (a ball in a V-groove, a stylus between
/// the walls of a slot) touches it in two places whose penalty forces nearly cancel. Coulomb
/// friction is mu N per place, mu (N1 + N2) in all, not mu |N1 + N2|: it needs the places apart.
///
/// What a patch is. The overlap of two sphere packings is a union of lenses, one per overlapping
/// leaf pair. Two lenses of one connected overlap region lie about one leaf diameter apart at
/// most (neighbouring leaves of a packing touch or overlap), while two separate regions are apart
/// by a gap of the size of the tool or the object. So two pairs are linked when their lens
/// centroids are closer than `kPatchLinkRadii` times the larger of their two smaller-sphere radii,
/// and a patch is a set of pairs connected by links. Normals are not compared: a curved contact
/// (a ball in a bowl) is one region however its normals turn.
///
/// How. One pass over the pairs grows axis-aligned boxes of lens centroids (world frame): a pair
/// joins every box it links to (the box grown by the link distance) and those boxes merge; then
/// boxes that link merge until none do (so the order of the pairs does not split a region). A
/// box approximates its region's hull: it may join two regions that a true graph search would
/// keep apart (an L-shaped region's box covers its corner), never split one. At most
/// kMaxContactPatches patches are kept: beyond it the one of least volume merges into the
/// nearest. O(pairs * kWorkingPatches), no allocation.
///
/// A pair's patch is the patch whose box is nearest to its lens centroid (patch_of): the same
/// answer for the model's build on the collision thread and for the held pairs re-evaluated on
/// the haptic thread, so the patches of one frame partition its pairs and their wrenches sum to
/// the whole one.

#include <cstdint>
#include <span>
#include <type_traits>

#include "uh/core/contact.hpp"
#include "uh/core/math.hpp"

namespace uh::forcecomp {

/// Most patches of one (object, tool) contact (each has its own friction stick point).
inline constexpr std::int32_t kMaxContactPatches = 4;
/// Two pairs are in one patch when their lens centroids are closer than this many times the
/// larger of their smaller-sphere radii (a leaf diameter: neighbouring leaves of one packing).
inline constexpr double kPatchLinkRadii = 2.0;

/// The patches of one frame's pairs (plain data; crosses threads inside a model).
struct ContactPatches {
  struct Patch {
    Vec3 lo{};  ///< box of the lens centroids, world frame at the frame's poses [L]
    Vec3 hi{};
    double volume = 0.0;  ///< sum of the pair volumes [L^3]
    double link = 0.0;    ///< the link distance of its pairs (largest) [L]; also how far its
                          ///< contact point may move on the tool from frame to frame and stay it
  };
  std::int32_t count = 0;  ///< 0: no pair overlaps
  Patch patch[kMaxContactPatches]{};

  /// The patch of a pair of the frame: the one whose box is nearest its lens centroid (ties: the
  /// lower index); 0 when there is none. Real-time safe, O(count).
  std::int32_t patch_of(const SpherePairContact& pair) const;
};
static_assert(std::is_trivially_copyable_v<ContactPatches>);

/// Which pairs an evaluation takes: all (no patches), or those of one patch.
struct PatchSelection {
  const ContactPatches* patches = nullptr;
  std::int32_t index = 0;
  bool includes(const SpherePairContact& pair) const {
    return patches == nullptr || patches->patch_of(pair) == index;
  }
};

/// Splits the pairs of one (object, tool) frame into patches (see the file comment); pairs of
/// zero volume (the contact margin's) take no part. Any thread; no allocation; O(pairs).
ContactPatches find_contact_patches(std::span<const SpherePairContact> pairs);

}  // namespace uh::forcecomp
