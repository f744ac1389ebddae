#pragma once
// Batched leaf pairs of the volume query (private to Collette).
//
// The traversal appends the leaf pairs whose spheres may overlap to a LeafBatch (structure of
// arrays, B's sphere already in A's frame) and evaluates them a SIMD group at a time with
// lens_lanes() (volume_fast_path.inl): the same float operations, in the same order, as
// uh::sphere_overlap<float> and the scalar pair evaluation of VolumeQuery, so every lane is bit for
// bit the scalar result (IEEE add, mul, div and sqrt are correctly rounded in every lane, and the
// build does not contract a * b + c into fused multiply-adds). The caller then walks the lanes in
// order, so pairs are stored and summed in the scalar order too: the totals are identical, not
// merely close.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace uh::collette::detail {

/// Leaf pairs waiting for evaluation. Lanes past `count` up to the next multiple of 16 (the widest
/// group) are zero spheres at the origin (apart: never overlap), so a group may read them.
struct LeafBatch {
  static constexpr int kCapacity = 256;
  static constexpr int kPad = 16;
  // each array is a whole number of cache lines, so all start on one
  alignas(64) float ax[kCapacity + kPad], ay[kCapacity + kPad], az[kCapacity + kPad], ar[kCapacity + kPad];
  alignas(64) float bx[kCapacity + kPad], by[kCapacity + kPad], bz[kCapacity + kPad], br[kCapacity + kPad];
  std::int32_t leaf_a[kCapacity], leaf_b[kCapacity];
  int count = 0;

  /// Pair i: the traversal keeps the count in a register while it appends, and stores it before
  /// the batch is evaluated.
  [[gnu::always_inline]] inline void set(int i, float xa, float ya, float za, float ra, float xb, float yb, float zb,
                                         float rb, std::int32_t la, std::int32_t lb) {
    ax[i] = xa;
    ay[i] = ya;
    az[i] = za;
    ar[i] = ra;
    bx[i] = xb;
    by[i] = yb;
    bz[i] = zb;
    br[i] = rb;
    leaf_a[i] = la;
    leaf_b[i] = lb;
  }

  /// Zero spheres from `count` up to the next multiple of kPad.
  void pad() {
    for (int i = count; i < ((count + kPad - 1) / kPad) * kPad; ++i) ax[i] = ay[i] = az[i] = ar[i] = bx[i] = by[i] = bz[i] = br[i] = 0.f;
  }
};

/// B's blocks moved into A's frame during one run, each when a visit first needs it: a B node meets
/// about seven A nodes in a deep contact (4,388 visits, 594 distinct B nodes on the benchmark's deep
/// random poses), so its children are moved once instead of at every visit. Block k's moved
/// children sit at data() + k * 4 * width (the layout of SphereTree::Blocks::bounds); they are this
/// run's when stamp[k] == run. Owned per traversal thread, like the batch.
struct MovedBlocks {
  struct alignas(64) Line {
    float v[16];
  };
  std::vector<Line> lines;
  std::vector<std::uint32_t> stamp;
  std::uint32_t run = 0;

  /// Starts a run over `blocks` blocks of `width` lanes: grows (only) past every earlier run's
  /// need, and invalidates every block.
  void begin(std::int32_t blocks, int width) {
    const auto n = static_cast<std::size_t>(blocks);
    if (lines.size() < (n * 4 * static_cast<std::size_t>(width) + 15) / 16)
      lines.resize((n * 4 * static_cast<std::size_t>(width) + 15) / 16);
    if (stamp.size() < n) stamp.resize(n, run);
    if (++run == 0) {  // wrapped: no stamp may equal a later run
      std::fill(stamp.begin(), stamp.end(), 0u);
      run = 1;
    }
  }
  float* data() { return lines.empty() ? nullptr : lines.front().v; }
};

/// What lens_lanes() computes per lane, in A's frame: lens volume (0 unless the spheres overlap),
/// intersection disk area, unit normal from A's centre to B's, lens centroid.
struct LensLanes {
  alignas(32) float volume[16], area[16], nx[16], ny[16], nz[16], cx[16], cy[16], cz[16];
};

inline constexpr float kPiF = static_cast<float>(3.14159265358979323846264338327950288L);
// the constants sphere_overlap<float> folds: (4/3) pi, pi/3
inline constexpr float kFourThirdsPiF = 4.f / 3.f * kPiF;
inline constexpr float kPiThirdF = kPiF / 3.f;

}  // namespace uh::collette::detail
