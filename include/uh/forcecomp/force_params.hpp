#pragma once
/// \file
/// Physical parameters of one object taking part in force computation (ForceComp).

#include "uh/core/math.hpp"

namespace uh::forcecomp {

/// Which forces a ForceComponent computes.
enum class ForceMode {
  k3Dof,  ///< force only; the torque of every result is zero (point-like tool)
  k6Dof,  ///< force and torque about the tool's centre of mass
};

/// Which object of a ContactFrame (A or B) the forces are computed for. Collette writes each
/// pair's normal from a's centre towards b's centre, so the force on B is +normal, on A -normal.
enum class ContactSide {
  kA,
  kB,
};

/// Physical parameters of one object (options aggregate, b2DefaultBodyDef style).
///
/// Units: L is the length unit of the contact data (metres when meshes are in metres). The
/// volumetric force is eps_c * overlap volume, so `force_scale` is in N / L^3; `damping` is an
/// ordinary linear damping coefficient in N s / L (see penalty_force.hpp for why).
struct ForceParams {
  double mass_kg = 0.1;                 ///< mass [kg], > 0; used by simulated tools (VirtualCoupling proxy)
  Vec3 center_of_mass_body{};           ///< centre of mass in the body (mesh) frame [L]; torques are about it
  double force_scale = 2.0e5;           ///< eps_c [N / L^3], >= 0
  double damping = 0.0;                 ///< eps_d [N s / L], >= 0; total damping along a common normal
  /// Overlap volume from which the full damping eps_d acts [L^3], >= 0. 0 (default): the paper's
  /// reading, full damping from the first touching pair on, which is a force step of eps_d * v
  /// at contact onset. V_d > 0: the damping shares are vol_ij / max(Vol_total, V_d), so the
  /// damping ramps up with the overlap and is continuous at contact (penalty_force.hpp).
  double damping_full_volume = 0.0;
  /// |force| limit of this object as a tool [N], > 0. Applied by the session's limit chain
  /// (haptico::ForceLimiter) together with the device's and the safety limits: the smallest wins.
  double max_force_n = 10.0;
  double max_torque_nm = 0.5;  ///< |torque| limit [N m], > 0; see max_force_n
};

}  // namespace uh::forcecomp
