#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "uh/core/result.hpp"
#include "uh/soft/tet_mesh.hpp"

namespace uh::soft {

/// Linear isotropic elasticity with mass and Rayleigh damping, C = alpha M + beta K.
struct ElasticMaterial {
  double young_modulus_pa = 1.0e5;  ///< E [Pa], > 0
  double poisson_ratio = 0.3;       ///< nu, in [0, 0.5)
  double density_kg_m3 = 1000.0;    ///< rho [kg/m^3], > 0
  double mass_damping_per_s = 0.0;  ///< alpha [1/s], >= 0; also slows rigid motion (drag)
  double stiffness_damping_s = 0.0; ///< beta [s], >= 0; damps deformation only
};

/// The nodes of `mesh` inside the box [min, max] (bounds included) [m], object frame.
std::vector<std::int32_t> nodes_in_box(const TetMesh& mesh, const Eigen::Vector3d& min, const Eigen::Vector3d& max);

/// Corotational linear FEM on linear tetrahedra (Mueller and Gross 2004): each element's rotation is
/// the polar decomposition of its deformation gradient, its forces are the linear ones in that
/// rotated frame. Lumped mass from the density. Steps are implicit (backward Euler), linearised
/// with the rotations of the step's start, and solved by conjugate gradients preconditioned with a
/// sparse LDL^T factorisation of an earlier step's system (same pattern, analysed once), which is
/// refactored only when the iterations do not converge quickly. Fixed nodes are eliminated: they
/// stay at their held position (the rest position unless moved with `hold`).
/// Not thread-safe: one simulation thread owns it. Not real-time: the assembly writes into fixed
/// slots, but Eigen's products, solves and factorisations may allocate.
class CorotationalFem {
 public:
  /// A model of `mesh` (positively oriented tetrahedra of nonzero volume) with `fixed` nodes held.
  /// Fails (kInvalid) on a bad material or node index, (kMesh) on an empty or degenerate mesh.
  static Result<CorotationalFem> create(TetMesh mesh, const ElasticMaterial& material,
                                        const std::vector<std::int32_t>& fixed);

  /// One backward-Euler step of `dt_s` [s] under `external_forces` [N] (one per node, object frame;
  /// those on fixed nodes are ignored). Fails when dt_s is not positive and finite, the forces are
  /// not one finite vector per node, or the factorisation fails; the state is then unchanged.
  Status step(double dt_s, const std::vector<Eigen::Vector3d>& external_forces);

  /// The static equilibrium under `external_forces` (no inertia, no damping), by at most
  /// `max_iterations` linear solves, each with the rotations of the last iterate, until no node
  /// moves more than `tolerance_m`. Needs fixed nodes (a free body has no equilibrium); velocities
  /// are set to zero. Returns the solves it took.
  Result<int> solve_static(const std::vector<Eigen::Vector3d>& external_forces, int max_iterations = 50,
                           double tolerance_m = 1e-12);

  /// Sets every node's position [m] and velocity [m/s] (one finite vector per node each): an
  /// initial shape and motion. Fixed nodes stay held where `hold` put them (their rest position).
  Status set_state(std::vector<Eigen::Vector3d> positions, std::vector<Eigen::Vector3d> velocities);

  /// Holds fixed node `node` at `position` [m] from the next step or solve on (a prescribed motion).
  Status hold(std::int32_t node, const Eigen::Vector3d& position);

  const TetMesh& mesh() const { return mesh_; }
  const std::vector<Eigen::Vector3d>& positions() const { return positions_; }    ///< [m]
  const std::vector<Eigen::Vector3d>& velocities() const { return velocities_; }  ///< [m/s]
  const std::vector<double>& node_masses() const { return masses_; }              ///< lumped [kg]
  bool is_fixed(std::int32_t node) const { return free_index_[static_cast<std::size_t>(node)] < 0; }
  int free_dofs() const { return static_cast<int>(rhs_.size()); }
  /// How many times the system was factorised (the others were solved by iterations on an older
  /// factorisation).
  int factorisations() const { return factorisations_; }
  /// Conjugate-gradient iterations of the last solve (0 when it was factorised and solved directly).
  int last_iterations() const { return iterations_; }
  /// Turns of the rotation extraction over all elements and steps so far.
  std::int64_t rotation_turns() const { return rotation_turns_; }

 private:
  using Block = Eigen::Matrix3d;
  struct Element {
    std::array<std::int32_t, 4> nodes{};
    Eigen::Matrix3d rest_inverse;     // inverse of the rest edge matrix [X1-X0, X2-X0, X3-X0]
    std::array<Block, 16> stiffness;  // rest stiffness K_ab [N/m], a * 4 + b
    Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
    Eigen::Quaterniond quaternion = Eigen::Quaterniond::Identity();  // the same, warm start of the next
  };

  CorotationalFem() = default;
  void build_pattern();
  void update_rotations();
  void elastic_forces(std::vector<Eigen::Vector3d>& forces) const;
  Status solve_increment(double mass_coefficient, double stiffness_coefficient,
                         const std::vector<Eigen::Vector3d>& loads);
  Status solve_system();
  bool conjugate_gradients();
  Status check_loads(const std::vector<Eigen::Vector3d>& external_forces) const;
  double apply_increment(double dt_s);

  TetMesh mesh_;
  ElasticMaterial material_;
  std::vector<Element> elements_;
  std::vector<Eigen::Vector3d> positions_;
  std::vector<Eigen::Vector3d> velocities_;
  std::vector<Eigen::Vector3d> held_;      // target positions of fixed nodes
  std::vector<double> masses_;
  std::vector<std::int32_t> free_index_;   // node -> its index among free nodes, -1 when fixed
  Eigen::SparseMatrix<double> system_;     // over free DOFs, fixed pattern
  std::vector<std::int32_t> block_slots_;  // per element block (a, b) and column c: value index of row 3 b'
  std::vector<std::int32_t> diagonal_slots_;
  // owned through a pointer: Eigen's solvers cannot be moved
  std::unique_ptr<Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>> solver_;
  bool factorised_ = false;
  int factorisations_ = 0;
  int iterations_ = 0;
  std::int64_t rotation_turns_ = 0;
  Eigen::VectorXd rhs_;
  Eigen::VectorXd increment_;
  Eigen::VectorXd residual_, preconditioned_, direction_, product_;  // scratch of the iterations
  std::vector<Eigen::Vector3d> forces_;    // scratch: elastic + external loads
};

}  // namespace uh::soft
