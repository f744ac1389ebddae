#pragma once
/// \file
/// WrenchModel: a local model of the penalty wrench on the tool around the pose at which a
/// collision frame was found, so that the haptic tick renders contact in constant time.
///
/// Built once per collision frame on the collision thread (O(pairs)): the static wrench W0 at the
/// frame's tool pose, its 6x6 derivative S = dW/dx with respect to the tool's pose, the 6x6
/// damping matrix D, and a trust range. The haptic tick evaluates
///
///     W(x, v) = W0 + S * clamp(x - x0) - D * v                                            (O(1))
///
/// where x - x0 = (displacement of the tool's centre of mass [L], rotation vector of
/// R R0^T [rad]), both world frame, and v = the tool's twist relative to the other object at the
/// tool's centre of mass (linear [L/s], angular [rad/s]). Rows of W: force [N], torque about the
/// centre of mass [N m], world frame.
///
/// The derivative is analytic, per pair, under the law in use (penalty_force.hpp). A pair whose
/// centres are d apart along the unit n (from the other object's sphere to the tool's) pushes the
/// tool with f = s(d) n, s = k/(c_A c_B) * area(d) (gradient law) or eps_c * vol(d) (paper law),
/// and ds/dd = k/(c_A c_B) * darea/dd or -eps_c * area. Moving the tool's sphere by dc gives
/// df = K dc with K = s' n n^T + (s/d)(I - n n^T); a tool motion (t, theta) about the centre of
/// mass A_m moves it by t + theta x r_t (r_t = c_t - A_m). The torque may be taken about any point
/// of the centre line (f is parallel to it): (c_o - A_m) x f, with the other object's sphere
/// centre c_o fixed and A_m moving with t. Hence, summed over the pairs:
///
///     dF/dt = K,   dF/dtheta = -K [r_t]x,   dtau/dt = [f]x + [r_o]x K,   dtau/dtheta = -[r_o]x K [r_t]x.
///
/// Damping: each pair's share vol/max(Vol_total, V_d') of eps_d along the row j = (n, r_o x n)
/// gives D = eps_d sum share j j^T (the per-pair clamp of f at zero is not modelled: it acts only
/// where the tool leaves faster than the spring pushes).
///
/// Trust range. The model is exact to first order; it goes wrong where pairs start or stop
/// overlapping, which happens over a fraction of the smaller sphere of the pairs. The trust
/// translation is `trust_fraction` times the force-weighted mean radius of the smaller sphere of
/// each pushing pair; the trust rotation turns the force-weighted RMS lever arm by as much.
/// Beyond it the displacement is scaled back onto the trust boundary (the wrench holds the
/// model's value there); WrenchModelRenderer adds the further fallback to a held wrench.
///
/// Everything here is plain data and free functions; real-time safe apart from the build, which
/// is O(pairs) but does not allocate either.

#include <cstdint>
#include <span>
#include <type_traits>

#include "uh/core/contact.hpp"
#include "uh/core/math.hpp"
#include "uh/forcecomp/contact_patches.hpp"
#include "uh/forcecomp/penalty_force.hpp"
#include "uh/forcecomp/virtual_coupling.hpp"  // rotation_vector
#include "uh/forcecomp/wrench.hpp"

namespace uh::forcecomp {

/// How a WrenchModel is built and rendered (options aggregate).
struct WrenchModelOptions {
  /// Trust translation as a share of the force-weighted mean radius of the smaller sphere of the
  /// pairs, > 0 (see the file comment).
  double trust_fraction = 0.25;
  /// Beyond this many trust ranges the renderer stops following the model and holds the wrench it
  /// rendered last (until a new frame arrives or the tool comes back), >= 1.
  double hold_beyond = 2.0;
  /// Blend time when a new model arrives [s]; 0: the interval between the last two frames
  /// (clamped to [kMinBlendS, kMaxBlendS]; 10 ms until two have arrived), so that the blend ends
  /// as the next frame comes.
  double blend_s = 0.0;
};

/// A 6x6 matrix, row-major: rows (force xyz, torque xyz), columns (translation xyz, rotation xyz).
using Matrix6 = double[6][6];

/// The local wrench model of one collision frame. Trivially copyable (crosses threads in a
/// LatestValue), about 700 bytes.
struct WrenchModel {
  bool contact = false;            ///< false: no pushing pair (the model is the zero wrench)
  bool six_dof = true;             ///< false: the torque rows are zero (3-DOF mode)
  std::uint64_t sequence = 0;      ///< the frame's sequence
  double time_s = 0.0;             ///< the frame's time [s] (steady clock of the query start)
  std::int32_t pair_count = 0;     ///< pairs with positive volume in the frame
  Quat tool_rotation{};            ///< the tool's world rotation at the frame
  Vec3 center_of_mass_world{};     ///< the tool's centre of mass at the frame [L]
  Wrench wrench{};                 ///< static wrench W0 at the frame pose (no damping)
  double total_volume = 0.0;       ///< Vol_total of the frame's pairs [L^3]
  /// Where the frame was found, for stages after the penalty (friction, texture): the poses of the
  /// tool and the other object, the volume-weighted mean of the lens centroids [L] and
  /// dVol_total/d(tool position) = -sum area * n [L^2], world frame.
  Pose world_from_tool{};
  Pose world_from_other{};
  Vec3 volume_centroid_world{};
  Vec3 volume_gradient_world{};
  Matrix6 stiffness{};             ///< S = dW/d(pose) [N/L, N/rad; N m/L, N m/rad]
  Matrix6 damping{};               ///< D: W -= D * relative twist [N s/L, ...]
  double trust_translation = 0.0;  ///< [L], > 0 when contact
  double trust_rotation = 0.0;     ///< [rad], > 0 when contact
};
static_assert(std::is_trivially_copyable_v<WrenchModel>);

/// Builds the model of the pairs found with the objects at world_from_a, world_from_b, under
/// `input` (law, stiffness, coverage product, damping, mode, tool side); input.tool's centre of
/// mass must be the tool's at the frame pose (its velocities are not used). Only the spheres of
/// each pair are read (volumes, normals and points are recomputed in double). With a patch
/// `selection`, the model of that patch's pairs only (contact_patches.hpp): its damping is scaled
/// by the volume of all the pairs, as in the whole model, so that W0, S and D of the patches sum
/// to the whole model's (its total_volume, centroid and gradient are the patch's own). Any thread;
/// does not allocate; O(pairs).
WrenchModel build_wrench_model(std::span<const SpherePairContact> pairs, const Pose& world_from_a,
                               const Pose& world_from_b, const PenaltyInput& input,
                               const WrenchModelOptions& options = {}, const PatchSelection& selection = {});

/// Same from a collision frame at the poses it used, with its sequence and time: the one place
/// that reads a ContactFrame's pair storage for the model.
WrenchModel build_wrench_model(const ContactFrame& frame, const PenaltyInput& input,
                               const WrenchModelOptions& options = {});

/// One evaluation of a model.
struct WrenchModelSample {
  Wrench wrench{};     ///< on the tool, world frame, torque about its centre of mass
  double reach = 0.0;  ///< how far the pose is from the frame's, in trust ranges (> 1: clamped)
};

/// The model at the tool's current rotation and motion (its centre of mass and velocities),
/// the other object moving with `other`. Real-time safe, O(1).
WrenchModelSample evaluate_wrench_model(const WrenchModel& model, const Quat& tool_rotation,
                                        const BodyMotion& tool, const BodyMotion& other = {});

/// Renders a stream of WrenchModels on the haptic thread: evaluates the newest at every tick,
/// blends from what it rendered last when a new one arrives (the difference fades out linearly
/// over the blend time, so a frame's arrival makes no step), and holds the last wrench when the
/// tool is more than `hold_beyond` trust ranges from the model's pose.
///
/// Threads: one owner (the haptic thread). Memory: holds one model by value; take() and render()
/// never allocate, lock, throw or log.
class WrenchModelRenderer {
 public:
  static constexpr double kMinBlendS = 1e-4;
  static constexpr double kMaxBlendS = 0.05;

  explicit WrenchModelRenderer(const WrenchModelOptions& options = {}) : options_(options) {}

  /// A new model arrived; the next render() blends into it. Real-time safe.
  void take(const WrenchModel& model);
  /// The wrench at tick time `now_s` for the tool's rotation and motion. Real-time safe, O(1).
  Wrench render(double now_s, const Quat& tool_rotation, const BodyMotion& tool,
                const BodyMotion& other = {});
  /// Forgets the model and the blend (zero wrench from the next render on).
  void reset();

  /// True while there is something to render: a model in contact or a blend still fading out.
  bool active(double now_s) const;
  const WrenchModel& model() const { return model_; }
  /// Ticks rendered with the displacement clamped to the trust range, and holding the last wrench.
  std::uint64_t clamped_ticks() const { return clamped_ticks_; }
  std::uint64_t held_ticks() const { return held_ticks_; }

 private:
  WrenchModelOptions options_;
  WrenchModel model_{};
  bool have_model_ = false;
  bool rebase_ = false;   // a model arrived: the next render starts a blend
  bool holding_ = false;  // beyond hold_beyond trust ranges
  Wrench last_{};         // what render() returned last
  double last_s_ = 0.0;   // when
  bool have_last_ = false;
  Wrench offset_{};  // blend: added to the model, fading to zero
  double blend_start_s_ = 0.0;
  double blend_s_ = 0.0;
  double frame_interval_s_ = 0.0;
  std::uint64_t clamped_ticks_ = 0;
  std::uint64_t held_ticks_ = 0;
};

}  // namespace uh::forcecomp
