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

/// Which force law turns the overlapping sphere pairs into a force (docs/forcecomp.md, "The force laws").
enum class ForceLaw {
  /// Default. F = -k / (c_A c_B) * dV/dx_B: minus the gradient of the packings' overlap volume V,
  /// each pair pushing with k / (c_A c_B) times its intersection disk area along its centre line.
  /// Conservative (the gradient of the potential k V / (c_A c_B)); `stiffness` k is a pressure
  /// [N / L^2]; calibrated by the packings' coverages so the feel does not depend on the sphere count.
  kGradient,
  /// The paper's eq. 1: each pair pushes with eps_c times its lens volume along its centre line;
  /// `force_scale` eps_c [N / L^3]; not calibrated (a finer packing feels harder).
  kPaper,
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
/// gradient law's `stiffness` k is a pressure in N / L^2 (force per unit of contact area: a flat
/// face pressed in feels k * its area at any depth, a round tip of radius r is a spring of about
/// 2 pi r k N / L); the paper law's `force_scale` eps_c is in N / L^3 (force per overlap volume);
/// `damping` is an ordinary linear damping coefficient in N s / L (see penalty_force.hpp for why).
struct ForceParams {
  double mass_kg = 0.1;                 ///< mass [kg], > 0; used by simulated tools (VirtualCoupling proxy)
  Vec3 center_of_mass_body{};           ///< centre of mass in the body (mesh) frame [L]; torques are about it
  ForceLaw law = ForceLaw::kGradient;   ///< which of the two laws below renders the contact
  double stiffness = 2.0e4;  ///< gradient law: k [N / L^2], >= 0 (2e4 N/m^2: a 4 mm tip is a 0.5 N/mm spring)
  double force_scale = 2.0e5;           ///< paper law: eps_c [N / L^3], >= 0
  double damping = 0.0;                 ///< eps_d [N s / L], >= 0; total damping along a common normal
  /// Overlap volume from which the full damping eps_d acts [L^3], >= 0 (the ramped reading,
  /// penalty_force.hpp): the damping shares are vol_ij / max(Vol_total, V_d), so the damping
  /// ramps up with the overlap and is continuous at contact. The default, 2e-8 (20 mm^3 in
  /// metres: a 4 mm tip about 1.3 mm deep), ramps over the first millimetre or so; 0 is the
  /// paper's reading, the full damping from the first touching pair on, a force step of eps_d * v
  /// at contact onset. With the gradient law the volume compared is the calibrated one, V / (c_A c_B).
  double damping_full_volume = 2.0e-8;
  /// |force| limit of this object as a tool [N], > 0. Applied by the session's limit chain
  /// (haptico::ForceLimiter) together with the device's and the safety limits: the smallest wins.
  double max_force_n = 10.0;
  double max_torque_nm = 0.5;  ///< |torque| limit [N m], > 0; see max_force_n
};

}  // namespace uh::forcecomp
