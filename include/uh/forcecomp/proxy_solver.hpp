#pragma once
/// \file
/// ProxySolver: one step of a 6-DOF god-object. The simulated tool (proxy) moves as close as it can
/// to where the device's handle wants it, subject to linearised non-penetration constraints, one
/// per nearby sphere pair (after Ortega, Redon and Coquillart 2007, on sphere pairs as Wang et al.
/// 2013 do).
///
/// A step delta = (t, w) is a translation t [m] and a small rotation w [rad] (axis times angle,
/// about the proxy's origin, world frame). It minimises the weighted distance to the wanted step,
///     1/2 |t - t*|^2 + 1/2 R^2 |w - w*|^2,
/// subject to, for every constraint k (a sphere pair with unit normal n_k pushing the tool out,
/// a contact point at lever r_k from the proxy's origin and a gap g_k it may still close),
///     n_k . t + (r_k x n_k) . w >= -g_k.
/// R (ProxySolverOptions::radius_m) makes turning and sliding comparable: a rotation w moves a point
/// at distance R by about R |w|.
///
/// The solver is Goldfarb and Idnani's dual active-set method (Math. Programming 27, 1983) on this
/// projection problem: it starts at the wanted step, adds the most violated constraint, drops those
/// whose multiplier would turn negative, and ends at the exact minimiser in finitely many steps
/// (at most six constraints are active in six dimensions). Its memory is fixed; solve() is
/// real-time safe (no allocation, lock, exception or logging).

#include <cstdint>
#include <span>
#include <type_traits>
#include <vector>

#include "uh/core/math.hpp"

namespace uh::forcecomp {

/// One linearised non-penetration constraint. Plain data.
struct ProxyConstraint {
  Vec3 normal{};  ///< unit, world frame: the direction that moves the tool out of the object
  Vec3 lever{};   ///< contact point minus the proxy's origin, world frame [m]
  double gap = 0.0;  ///< how far the contact may still close along `normal` [m]; < 0: too deep already
  std::int32_t tag = -1;  ///< the caller's (which object it is with); the solver does not read it
};
static_assert(std::is_trivially_copyable_v<ProxyConstraint>);

/// Options of a ProxySolver (aggregate; designated initialisers).
struct ProxySolverOptions {
  double radius_m = 0.01;     ///< R, the length that weighs rotation against translation [m], > 0
  bool rotate = true;         ///< false: the rotation is fixed at the wanted one (w = w*, constraints on t only)
  int max_iterations = 64;    ///< most constraint additions and drops per solve
  double tolerance_m = 1e-9;  ///< a constraint violated by less than this counts as met [m]
  /// Most constraints one solve takes (its scratch is allocated for them at construction); a
  /// longer span is an error of the caller (asserted), its rest ignored.
  std::int32_t max_constraints = 4096;
};

/// The outcome of one solve. Plain data.
struct ProxyStep {
  Vec3 translation{};  ///< t [m], world frame
  Vec3 rotation{};     ///< w [rad], axis times angle, world frame
  std::int32_t active = 0;      ///< constraints active at the solution (0-6)
  std::int32_t active_index[6] = {-1, -1, -1, -1, -1, -1};  ///< which (indices into the span), `active` of them
  std::int32_t iterations = 0;  ///< additions and drops made
  /// The constraints can all be met and the step is their exact minimiser. False when they
  /// contradict each other (a tool pinched deeper than it may be from two sides) or the iteration
  /// limit was reached: the step is then the last iterate, which meets the active constraints.
  bool converged = true;
};
static_assert(std::is_trivially_copyable_v<ProxyStep>);

/// Projects a wanted step onto the constraints (see the file comment).
class ProxySolver {
 public:
  explicit ProxySolver(const ProxySolverOptions& options = {});

  /// The step nearest to (t*, w*) that meets every constraint. Real-time safe. Not thread-safe (it
  /// works in its own scratch): one solver per thread.
  ProxyStep solve(std::span<const ProxyConstraint> constraints, const Vec3& wanted_translation,
                  const Vec3& wanted_rotation);

  const ProxySolverOptions& options() const { return options_; }

 private:
  ProxySolverOptions options_;
  std::vector<double> rows_;  // per constraint: its row scaled to unit length (6) and its bound
};

}  // namespace uh::forcecomp
