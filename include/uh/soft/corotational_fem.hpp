#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "uh/core/result.hpp"
#include "uh/soft/block_preconditioner.hpp"
#include "uh/soft/tet_mesh.hpp"

namespace uh::soft {

class BackgroundFactorisation;
}  // namespace uh::soft
namespace uh {
class SideThread;
}  // namespace uh
namespace uh::soft {

/// Linear isotropic elasticity with mass and Rayleigh damping, C = alpha M + beta K.
struct ElasticMaterial {
  double young_modulus_pa = 1.0e5;  ///< E [Pa], > 0
  double poisson_ratio = 0.3;       ///< nu, in [0, 0.5)
  double density_kg_m3 = 1000.0;    ///< rho [kg/m^3], > 0
  double mass_damping_per_s = 0.0;  ///< alpha [1/s], >= 0; also slows rigid motion (drag)
  double stiffness_damping_s = 0.0; ///< beta [s], >= 0; damps deformation only
};

/// How a step's linear system is solved. The default iterates: conjugate gradients preconditioned by
/// the factorisation of an earlier step's system, refactorised only when the iterations do not
/// reach `relative_residual` within `max_iterations`. `direct` factorises every system and solves
/// it exactly (to rounding): the reference the iterations are tested against, several times slower.
struct SolverOptions {
  double relative_residual = 1e-6;  ///< stop when |b - A dx| <= this * |b|, in (0, 1)
  int max_iterations = 10;          ///< beyond this the system is factorised and solved directly, >= 1
  bool direct = false;              ///< factorise and solve every system directly
};

/// A node pressed by a rigid obstacle, linearised at the node's current position: the `force` [N]
/// on it, object frame, and its `stiffness` [N/m] = -d force / d position (symmetric, positive
/// semidefinite), which only speeds up the iterations: the equilibrium is where the forces balance.
struct NodeContact {
  std::int32_t node = 0;
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  Eigen::Matrix3d stiffness = Eigen::Matrix3d::Zero();
};

/// An obstacle's contacts at the node positions [m]: appends to `contacts` (given empty) an entry
/// per pressed node; entries naming the same node add up (several obstacles may press one node).
using ContactModel =
    std::function<void(const std::vector<Eigen::Vector3d>& positions, std::vector<NodeContact>& contacts)>;

/// The nodes of `mesh` inside the box [min, max] (bounds included) [m], object frame.
std::vector<std::int32_t> nodes_in_box(const TetMesh& mesh, const Eigen::Vector3d& min, const Eigen::Vector3d& max);

/// Corotational linear FEM on linear tetrahedra (Mueller and Gross 2004): each element's rotation is
/// the polar decomposition of its deformation gradient, its forces are the linear ones in that
/// rotated frame. Lumped mass from the density. Steps are implicit (backward Euler), linearised
/// with the rotations of the step's start, and solved by conjugate gradients preconditioned with a
/// sparse LDL^T factorisation of an earlier step's system (same pattern, analysed once, kept as a
/// single-precision copy in 3 x 3 node blocks), which is refactored only when the iterations do
/// not converge quickly (SolverOptions), in place or on a worker thread (factorise_in_background).
/// Fixed nodes are eliminated: they stay at their held position (the rest position unless moved
/// with `hold`). Not thread-safe: one simulation thread owns it (and its worker, when it has one). Not real-time: the assembly writes into fixed
/// slots, but Eigen's products, solves and factorisations may allocate.
class CorotationalFem {
 public:
  /// A model of `mesh` (positively oriented tetrahedra of nonzero volume) with `fixed` nodes held.
  /// Fails (kInvalid) on a bad material, solver option or node index, (kMesh) on an empty or
  /// degenerate mesh.
  static Result<CorotationalFem> create(TetMesh mesh, const ElasticMaterial& material,
                                        const std::vector<std::int32_t>& fixed, const SolverOptions& solver = {});
  ~CorotationalFem();
  CorotationalFem(CorotationalFem&&) noexcept;
  CorotationalFem& operator=(CorotationalFem&&) noexcept;

  /// With `on`, a stale preconditioner is refactorised on a worker thread while the steps iterate
  /// on with the old one (up to 4 x max_iterations), so a step never stops for a factorisation:
  /// for a simulation thread that must keep its rate (tens of milliseconds at 5,000 tetrahedra).
  /// The solves then depend on timing (each still reaches relative_residual); off (the default),
  /// every run of the same steps is the same. Starts or ends the worker thread.
  void factorise_in_background(bool on);

  /// With `on`, each step's element pass (rotations, forces, stiffness: a third of a step) runs on
  /// two threads, the elements on either side of a cut through the mesh at once and those across it
  /// after: the same sums in the same order as on one thread. Starts or ends the second thread.
  void assemble_on_two_threads(bool on);

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

  /// The same with an obstacle's position-dependent contact forces added to `external_forces`, each
  /// solve linearised with the contacts of the last iterate (forces on fixed nodes are ignored).
  /// Fails as solve_static does, and when a contact names no node or is not finite.
  Result<int> solve_static(const std::vector<Eigen::Vector3d>& external_forces, const ContactModel& contacts,
                           int max_iterations = 50, double tolerance_m = 1e-12);

  /// The move the next step would add per `loads` [N, one per node, object frame; fixed nodes'
  /// ignored] into `moves` [m, one per node, zero on fixed nodes]: the step's system
  /// (M (1/h^2 + alpha/h) + K' (1 + beta/h)) solved by its kept factorisation (single precision,
  /// of the rotations last factorised, the h of the last step): the object's compliance within one
  /// step, as a contact sees it. Fails before the first step or on loads that are not one finite
  /// vector per node.
  Status step_response(const std::vector<Eigen::Vector3d>& loads, std::vector<Eigen::Vector3d>& moves);

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
  /// How many of the worker's factorisations preconditioned the later steps (factorise_in_background).
  int background_factorisations() const { return background_factorisations_; }
  /// Conjugate-gradient iterations of the last solve (0 when it was factorised and solved directly).
  int last_iterations() const { return iterations_; }
  const SolverOptions& solver_options() const { return solver_options_; }
  /// Turns of the rotation extraction over all elements and steps so far.
  std::int64_t rotation_turns() const { return rotation_turns_; }

 private:
  struct Element {
    std::array<std::int32_t, 4> nodes{};
    std::array<Eigen::Vector3d, 4> gradients;  // of the linear shape functions at rest [1/m]
    double volume = 0.0;                        // at rest [m^3]
    Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
    Eigen::Quaterniond quaternion = Eigen::Quaterniond::Identity();  // the same, warm start of the next
  };

  CorotationalFem() = default;
  void order_free_nodes();
  void build_pattern();
  std::int64_t update_rotation(Element& element, const Eigen::Matrix3d& deformation);
  std::int64_t assemble_elements(const std::vector<std::int32_t>& elements, double stiffness_coefficient);
  void partition_elements();
  void assemble(double mass_coefficient, double stiffness_coefficient, const std::vector<Eigen::Vector3d>& loads,
                const std::vector<NodeContact>& contacts);
  void assemble_element(const Element& element, std::size_t index, const Eigen::Matrix3d& deformation,
                        double stiffness_coefficient);
  Status solve_system();
  Status factorise_and_solve();
  bool conjugate_gradients(int max_iterations);
  void multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const;
  void take_background_preconditioner();
  Status check_loads(const std::vector<Eigen::Vector3d>& external_forces) const;
  Status check_contacts(const std::vector<NodeContact>& contacts) const;
  double apply_increment(double dt_s);

  TetMesh mesh_;
  ElasticMaterial material_;
  SolverOptions solver_options_;
  double lambda_ = 0.0;  // Lame's first parameter [Pa]
  double mu_ = 0.0;      // shear modulus [Pa]
  std::vector<Element> elements_;
  std::vector<Eigen::Vector3d> positions_;
  std::vector<Eigen::Vector3d> velocities_;
  std::vector<Eigen::Vector3d> previous_velocities_;  // of the step before the last, for the first guess
  std::vector<Eigen::Vector3d> held_;      // target positions of fixed nodes
  std::vector<double> masses_;
  std::vector<std::int32_t> free_index_;   // node -> its index among free nodes, -1 when fixed
  Eigen::SparseMatrix<double> system_;     // over free DOFs, fixed pattern, lower triangle only
  std::vector<std::int32_t> block_slots_;  // per element node pair (a, b) and column c: value index of row 0
  std::vector<std::int32_t> diagonal_slots_;
  std::unique_ptr<SystemFactorisation> solver_;  // through a pointer: Eigen's solvers cannot be moved
  bool factorised_ = false;
  int factorisations_ = 0;
  int iterations_ = 0;
  std::int64_t rotation_turns_ = 0;
  Eigen::VectorXd rhs_;
  Eigen::VectorXd increment_;
  Eigen::VectorXd residual_, preconditioned_, direction_, product_;  // scratch of the iterations
  Eigen::VectorXd response_loads_, response_;                        // scratch of step_response
  BlockPreconditioner preconditioner_;  // of the last factorisation (in place or the worker's)
  BlockPreconditioner taken_;           // scratch: the worker's, before it is known to be the newest
  std::unique_ptr<BackgroundFactorisation> background_;
  std::array<std::vector<std::int32_t>, 3> element_sides_;  // elements below the cut, above it, across it
  std::unique_ptr<SideThread> side_thread_;                 // with assemble_on_two_threads
  int background_factorisations_ = 0;
  std::vector<Eigen::Vector3d> forces_;    // scratch: external loads and inertia
  std::vector<NodeContact> contacts_;      // scratch: the obstacle's contacts of the last iterate
};

}  // namespace uh::soft
