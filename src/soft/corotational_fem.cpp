#include "uh/soft/corotational_fem.hpp"

#include "background_factorisation.hpp"
#include "uh/core/side_thread.hpp"

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace uh::soft {
namespace {

// with a factorisation under way on the worker, the iterations may go on this many times as far
// as max_iterations before the system is factorised in place (a step a few times as long, rather
// than one tens of times as long)
constexpr int kBackgroundIterationFactor = 4;

// the rotation of F = R S for det F > 0, by Newton's iteration X <- (g X + X^-T / g) / 2 with
// Higham's scaling g: quadratic, a handful of iterations, orthogonal to 1e-12
bool polar_newton(const Eigen::Matrix3d& deformation, Eigen::Matrix3d& rotation) {
  constexpr int kMaxIterations = 20;
  // the iteration converges quadratically: once a change is below this, one more leaves an error
  // of about half its square (5e-13), far below what the forces notice
  constexpr double kLastButOne = 1e-6;
  // Higham's scaling speeds up the first iterations of a strongly stretched element; near the
  // rotation it is 1 and its square roots are saved
  constexpr double kScaledAbove = 1e-2;
  Eigen::Matrix3d x = deformation;
  double change = std::numeric_limits<double>::infinity();
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    const bool last = change < kLastButOne;
    // X^-T from the cofactors, the cross products of X's columns
    Eigen::Matrix3d inverse_transpose;
    inverse_transpose.col(0) = x.col(1).cross(x.col(2));
    inverse_transpose.col(1) = x.col(2).cross(x.col(0));
    inverse_transpose.col(2) = x.col(0).cross(x.col(1));
    const double determinant = x.col(0).dot(inverse_transpose.col(0));
    if (!(determinant > 0.0)) return false;
    inverse_transpose /= determinant;
    const double scale =
        change > kScaledAbove ? std::sqrt(std::sqrt(inverse_transpose.squaredNorm() / x.squaredNorm())) : 1.0;
    const Eigen::Matrix3d next = 0.5 * (scale * x + inverse_transpose / scale);
    change = (next - x).norm();
    x = next;
    if (last) {
      rotation = x;
      return true;
    }
  }
  return false;
}

constexpr std::size_t at(std::int32_t index) { return static_cast<std::size_t>(index); }

Status check_material(const ElasticMaterial& m) {
  const auto fail = [](const std::string& what) {
    return Error{"soft::CorotationalFem: " + what, ErrorKind::kInvalid};
  };
  if (!(m.young_modulus_pa > 0.0) || !std::isfinite(m.young_modulus_pa)) return fail("young_modulus_pa must be > 0");
  if (!(m.poisson_ratio >= 0.0 && m.poisson_ratio < 0.5)) return fail("poisson_ratio must be in [0, 0.5)");
  if (!(m.density_kg_m3 > 0.0) || !std::isfinite(m.density_kg_m3)) return fail("density_kg_m3 must be > 0");
  if (!(m.mass_damping_per_s >= 0.0) || !std::isfinite(m.mass_damping_per_s)) {
    return fail("mass_damping_per_s must be >= 0");
  }
  if (!(m.stiffness_damping_s >= 0.0) || !std::isfinite(m.stiffness_damping_s)) {
    return fail("stiffness_damping_s must be >= 0");
  }
  return Ok{};
}

Eigen::Matrix3d edge_matrix(const std::vector<Eigen::Vector3d>& x, const std::array<std::int32_t, 4>& t) {
  Eigen::Matrix3d edges;
  for (int i = 0; i < 3; ++i) edges.col(i) = x[at(t[at(i + 1)])] - x[at(t[0])];
  return edges;
}

// the rotation of F = R S, S symmetric positive: the iteration of Mueller et al. (2016, "A robust
// method to extract the rotational part of deformations"), turning `rotation` about the axis that
// makes R^T F more symmetric until it is symmetric. Warm-started from the last step's rotation it
// takes one or two turns; it never yields a reflection, even for an inverted element.
int extract_rotation(const Eigen::Matrix3d& deformation, Eigen::Quaterniond& rotation) {
  // a strongly stretched element converges slowly (about a dozen turns); a cap that leaves the
  // rest to the next step makes a rigid body creep, so the rotation is converged each time
  constexpr int kMaxTurns = 40;
  constexpr double kConverged = 1e-10;  // [rad]
  for (int turn = 0; turn < kMaxTurns; ++turn) {
    const Eigen::Matrix3d r = rotation.toRotationMatrix();
    Eigen::Vector3d axis = Eigen::Vector3d::Zero();
    double alignment = 0.0;
    for (int i = 0; i < 3; ++i) {
      axis += r.col(i).cross(deformation.col(i));
      alignment += r.col(i).dot(deformation.col(i));
    }
    axis /= std::abs(alignment) + 1e-9;
    const double angle = axis.norm();
    if (angle < kConverged) return turn;
    rotation = (Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis / angle)) * rotation).normalized();
  }
  return kMaxTurns;
}

bool all_finite(const std::vector<Eigen::Vector3d>& vectors) {
  return std::all_of(vectors.begin(), vectors.end(), [](const Eigen::Vector3d& v) { return v.allFinite(); });
}

Status check_solver(const SolverOptions& o) {
  if (!(o.relative_residual > 0.0 && o.relative_residual < 1.0)) {
    return Error{"soft::CorotationalFem: solver relative_residual must be in (0, 1)", ErrorKind::kInvalid};
  }
  if (o.max_iterations < 1) return Error{"soft::CorotationalFem: solver max_iterations must be >= 1", ErrorKind::kInvalid};
  return Ok{};
}

}  // namespace

std::vector<std::int32_t> nodes_in_box(const TetMesh& mesh, const Eigen::Vector3d& min, const Eigen::Vector3d& max) {
  std::vector<std::int32_t> inside;
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
    const Eigen::Vector3d& p = mesh.nodes[i];
    if ((p.array() >= min.array()).all() && (p.array() <= max.array()).all()) {
      inside.push_back(static_cast<std::int32_t>(i));
    }
  }
  return inside;
}

Result<CorotationalFem> CorotationalFem::create(TetMesh mesh, const ElasticMaterial& material,
                                                const std::vector<std::int32_t>& fixed, const SolverOptions& solver) {
  if (auto valid = check_material(material); !valid) return valid.error();
  if (auto valid = check_solver(solver); !valid) return valid.error();
  if (mesh.tets.empty()) return Error{"soft::CorotationalFem: the mesh has no tetrahedra", ErrorKind::kMesh};
  const auto node_count = static_cast<std::int32_t>(mesh.nodes.size());
  CorotationalFem fem;
  fem.free_index_.assign(mesh.nodes.size(), 0);
  for (const std::int32_t node : fixed) {
    if (node < 0 || node >= node_count) {
      return Error{"soft::CorotationalFem: fixed node " + std::to_string(node) + " is not a node of the mesh",
                   ErrorKind::kInvalid};
    }
    fem.free_index_[at(node)] = -1;
  }
  fem.lambda_ = material.young_modulus_pa * material.poisson_ratio /
                ((1.0 + material.poisson_ratio) * (1.0 - 2.0 * material.poisson_ratio));
  fem.mu_ = material.young_modulus_pa / (2.0 * (1.0 + material.poisson_ratio));
  fem.masses_.assign(mesh.nodes.size(), 0.0);
  fem.elements_.reserve(mesh.tets.size());
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    const auto& t = mesh.tets[e];
    if (std::any_of(t.begin(), t.end(), [&](std::int32_t n) { return n < 0 || n >= node_count; })) {
      return Error{"soft::CorotationalFem: tetrahedron " + std::to_string(e) + " names a node out of range",
                   ErrorKind::kMesh};
    }
    const Eigen::Matrix3d edges = edge_matrix(mesh.nodes, t);
    const double volume = edges.determinant() / 6.0;
    if (!(volume > 0.0)) {
      return Error{"soft::CorotationalFem: tetrahedron " + std::to_string(e) + " is inverted or flat",
                   ErrorKind::kMesh};
    }
    Element element;
    element.nodes = t;
    element.volume = volume;
    // gradients of the shape functions: rows of the inverse edge matrix, and minus their sum
    const Eigen::Matrix3d rest_inverse = edges.inverse();
    for (int i = 0; i < 3; ++i) element.gradients[at(i + 1)] = rest_inverse.row(i).transpose();
    element.gradients[0] = -(element.gradients[1] + element.gradients[2] + element.gradients[3]);
    for (const std::int32_t n : t) fem.masses_[at(n)] += material.density_kg_m3 * volume / 4.0;
    fem.elements_.push_back(element);
  }
  std::int32_t free_count = 0;
  for (auto& index : fem.free_index_) index = index < 0 ? -1 : free_count++;
  fem.material_ = material;
  fem.solver_options_ = solver;
  fem.positions_ = mesh.nodes;
  fem.held_ = mesh.nodes;
  fem.velocities_.assign(mesh.nodes.size(), Eigen::Vector3d::Zero());
  fem.previous_velocities_ = fem.velocities_;
  fem.forces_.assign(mesh.nodes.size(), Eigen::Vector3d::Zero());
  fem.mesh_ = std::move(mesh);
  fem.rhs_.setZero(3 * free_count);
  fem.increment_.setZero(3 * free_count);
  fem.order_free_nodes();
  fem.build_pattern();
  fem.partition_elements();
  return fem;
}

// renumbers the free nodes by Eigen's approximate minimum degree ordering of the free node graph
void CorotationalFem::order_free_nodes() {
  const auto count = static_cast<Eigen::Index>(rhs_.size() / 3);
  std::vector<Eigen::Triplet<double>> entries;
  for (const auto& element : elements_) {
    for (const std::int32_t a : element.nodes) {
      for (const std::int32_t b : element.nodes) {
        if (free_index_[at(a)] >= 0 && free_index_[at(b)] >= 0) entries.emplace_back(free_index_[at(a)], free_index_[at(b)], 1.0);
      }
    }
  }
  Eigen::SparseMatrix<double> graph(count, count);
  graph.setFromTriplets(entries.begin(), entries.end());
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> elimination;
  Eigen::AMDOrdering<int>()(graph, elimination);  // the k-th node eliminated is elimination.indices()[k]
  std::vector<std::int32_t> position(static_cast<std::size_t>(count));
  for (Eigen::Index k = 0; k < count; ++k) position[at(elimination.indices()[k])] = static_cast<std::int32_t>(k);
  for (auto& index : free_index_) {
    if (index >= 0) index = position[at(index)];
  }
}

// The system is symmetric: only its lower triangle is stored (the factorisation reads no more, and
// the products use it as a self-adjoint view), so a node pair's block is written once, in the rows
// of the node with the larger free index.
void CorotationalFem::build_pattern() {
  std::vector<Eigen::Triplet<double>> entries;
  for (const auto& element : elements_) {
    for (const std::int32_t a : element.nodes) {
      for (const std::int32_t b : element.nodes) {
        const std::int32_t fa = free_index_[at(a)];
        const std::int32_t fb = free_index_[at(b)];
        if (fa < 0 || fb < 0 || fa < fb) continue;
        for (int c = 0; c < 3; ++c) {
          for (int r = fa == fb ? c : 0; r < 3; ++r) entries.emplace_back(3 * fa + r, 3 * fb + c, 0.0);
        }
      }
    }
  }
  const auto dofs = static_cast<Eigen::Index>(rhs_.size());
  system_.resize(dofs, dofs);
  system_.setFromTriplets(entries.begin(), entries.end());
  system_.makeCompressed();
  const auto slot = [&](Eigen::Index row, Eigen::Index col) {
    const int* begin = system_.innerIndexPtr() + system_.outerIndexPtr()[col];
    const int* end = system_.innerIndexPtr() + system_.outerIndexPtr()[col + 1];
    return static_cast<std::int32_t>(std::lower_bound(begin, end, static_cast<int>(row)) - system_.innerIndexPtr());
  };
  block_slots_.assign(elements_.size() * 16 * 3, -1);
  for (std::size_t e = 0; e < elements_.size(); ++e) {
    for (std::size_t a = 0; a < 4; ++a) {
      for (std::size_t b = 0; b < 4; ++b) {
        const std::int32_t fa = free_index_[at(elements_[e].nodes[a])];
        const std::int32_t fb = free_index_[at(elements_[e].nodes[b])];
        if (fa < 0 || fb < 0 || fa < fb) continue;
        // column c of the block starts at its first stored row: row 0, or row c on the diagonal
        for (int c = 0; c < 3; ++c) {
          block_slots_[(e * 16 + a * 4 + b) * 3 + at(c)] = slot(3 * fa + (fa == fb ? c : 0), 3 * fb + c);
        }
      }
    }
  }
  diagonal_slots_.resize(at(static_cast<std::int32_t>(dofs)));
  for (Eigen::Index d = 0; d < dofs; ++d) diagonal_slots_[static_cast<std::size_t>(d)] = slot(d, d);
  solver_ = std::make_unique<SystemFactorisation>();
  solver_->analyzePattern(system_);
}

// Newton's polar iteration where the element is not inverted (fast, exact); the warm-started turns
// where it is (they never yield a reflection). Returns the turns taken.
std::int64_t CorotationalFem::update_rotation(Element& element, const Eigen::Matrix3d& deformation) {
  constexpr double kLeastVolumeRatio = 1e-3;
  if (deformation.determinant() > kLeastVolumeRatio && polar_newton(deformation, element.rotation)) {
    element.quaternion = Eigen::Quaterniond(element.rotation);
    return 0;
  }
  const std::int64_t turns = extract_rotation(deformation, element.quaternion);
  element.rotation = element.quaternion.toRotationMatrix();
  return turns;
}

// One element's elastic forces (into the right-hand side) and rotated stiffness (into the system).
// With the rest stiffness K_ab = V (lambda g_a g_b^T + mu g_b g_a^T + mu (g_a . g_b) I) of the shape
// gradients g, the rotated block R K_ab R^T is the same expression in the rotated gradients R g,
// and the force f_a = -R sum_b K_ab (R^T x_b - X_b) is -V R sigma g_a, sigma the linear stress of
// the strain sym(R^T F) - I: no 12 x 12 matrix is stored or multiplied.
void CorotationalFem::assemble_element(const Element& element, std::size_t index, const Eigen::Matrix3d& deformation,
                                       double stiffness_coefficient) {
  const Eigen::Matrix3d& rot = element.rotation;
  const Eigen::Matrix3d stretch = rot.transpose() * deformation;
  const Eigen::Matrix3d strain = 0.5 * (stretch + stretch.transpose()) - Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d stress = lambda_ * strain.trace() * Eigen::Matrix3d::Identity() + 2.0 * mu_ * strain;
  const Eigen::Matrix3d first_piola = element.volume * rot * stress;
  std::array<Eigen::Vector3d, 4> turned;
  std::array<std::int32_t, 4> free{};
  for (std::size_t a = 0; a < 4; ++a) {
    turned[a] = rot * element.gradients[a];
    free[a] = free_index_[at(element.nodes[a])];
    if (free[a] >= 0) rhs_.segment<3>(3 * free[a]) -= first_piola * element.gradients[a];
  }
  const double scale = stiffness_coefficient * element.volume;
  const auto block = [&](std::size_t a, std::size_t b) {
    Eigen::Matrix3d k = lambda_ * turned[a] * turned[b].transpose() + mu_ * turned[b] * turned[a].transpose();
    k.diagonal().array() += mu_ * element.gradients[a].dot(element.gradients[b]);
    return Eigen::Matrix3d(scale * k);
  };
  double* values = system_.valuePtr();
  for (std::size_t a = 0; a < 4; ++a) {
    for (std::size_t b = 0; b < 4; ++b) {
      if (free[a] < 0 && free[b] >= 0) {
        // a held node's prescribed motion loads the free node b
        const std::int32_t held = element.nodes[a];
        const Eigen::Vector3d motion = held_[at(held)] - positions_[at(held)];
        if (!motion.isZero(0.0)) rhs_.segment<3>(3 * free[b]) -= block(b, a) * motion;
        continue;
      }
      if (free[a] < 0 || free[b] < 0 || free[a] < free[b]) continue;
      const Eigen::Matrix3d k = block(a, b);
      const std::int32_t* slots = &block_slots_[(index * 16 + a * 4 + b) * 3];
      for (int c = 0; c < 3; ++c) {
        for (int r = free[a] == free[b] ? c : 0, i = 0; r < 3; ++r, ++i) values[slots[c] + i] += k(r, c);
      }
    }
  }
}

// The system (m M + k K' + contact stiffness) dx = loads + elastic forces + contact forces for the
// free nodes, K' the stiffness rotated by each element's current rotation; fixed nodes move to
// where they are held
void CorotationalFem::assemble(double mass_coefficient, double stiffness_coefficient,
                               const std::vector<Eigen::Vector3d>& loads, const std::vector<NodeContact>& contacts) {
  double* values = system_.valuePtr();
  std::fill(values, values + system_.nonZeros(), 0.0);
  for (std::size_t node = 0; node < positions_.size(); ++node) {
    const std::int32_t f = free_index_[node];
    if (f < 0) continue;
    rhs_.segment<3>(3 * f) = loads[node];
    for (int c = 0; c < 3; ++c) values[diagonal_slots_[at(3 * f + c)]] += mass_coefficient * masses_[node];
  }
  // the two sides' elements write disjoint entries (partition_elements): side by side when a
  // second thread is given, one after the other otherwise, in the same order either way
  std::int64_t turns[2] = {0, 0};
  const auto side = [&](int s) { turns[s] = assemble_elements(element_sides_[at(s)], stiffness_coefficient); };
  if (side_thread_) {
    side_thread_->run_beside([&] { side(0); }, [&] { side(1); });
  } else {
    side(0);
    side(1);
  }
  rotation_turns_ += turns[0] + turns[1] + assemble_elements(element_sides_[2], stiffness_coefficient);
  for (const NodeContact& contact : contacts) {
    const std::int32_t f = free_index_[at(contact.node)];
    if (f < 0) continue;
    rhs_.segment<3>(3 * f) += contact.force;
    for (int c = 0; c < 3; ++c) {
      for (int r = c, i = 0; r < 3; ++r, ++i) values[diagonal_slots_[at(3 * f + c)] + i] += contact.stiffness(r, c);
    }
  }
}

// Each element of `elements` (indices): its rotation from its deformation gradient, then its forces
// and stiffness into the system; returns the rotation extraction's turns.
std::int64_t CorotationalFem::assemble_elements(const std::vector<std::int32_t>& elements, double stiffness_coefficient) {
  std::int64_t turns = 0;
  for (const std::int32_t e : elements) {
    Element& element = elements_[at(e)];
    Eigen::Matrix3d deformation = Eigen::Matrix3d::Zero();
    for (std::size_t b = 0; b < 4; ++b) deformation += positions_[at(element.nodes[b])] * element.gradients[b].transpose();
    turns += update_rotation(element, deformation);
    assemble_element(element, at(e), deformation, stiffness_coefficient);
  }
  return turns;
}

// Splits the elements for an assembly on two threads: the nodes on either side of the median along
// the mesh's longest extent; an element with all its nodes on one side writes only that side's rows
// of the system and the right-hand side, so the two sides' elements can be assembled at once; the
// elements across the cut (a layer, a few per cent) come after.
void CorotationalFem::partition_elements() {
  Eigen::Vector3d low = positions_.front(), high = positions_.front();
  for (const Eigen::Vector3d& x : positions_) {
    low = low.cwiseMin(x);
    high = high.cwiseMax(x);
  }
  Eigen::Index axis = 0;
  (high - low).maxCoeff(&axis);
  std::vector<double> along;
  along.reserve(positions_.size());
  for (const Eigen::Vector3d& x : positions_) along.push_back(x[axis]);
  std::nth_element(along.begin(), along.begin() + static_cast<std::ptrdiff_t>(along.size() / 2), along.end());
  const double cut = along[along.size() / 2];
  for (auto& side : element_sides_) side.clear();
  for (std::size_t e = 0; e < elements_.size(); ++e) {
    int below = 0;
    for (const std::int32_t n : elements_[e].nodes) below += positions_[at(n)][axis] < cut ? 1 : 0;
    const std::size_t side = below == 4 ? 0 : below == 0 ? 1 : 2;
    element_sides_[side].push_back(static_cast<std::int32_t>(e));
  }
}

void CorotationalFem::assemble_on_two_threads(bool on) {
  if (!on) {
    side_thread_.reset();
  } else if (!side_thread_) {
    side_thread_ = std::make_unique<SideThread>();
  }
}

void CorotationalFem::multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
  y.noalias() = system_.selfadjointView<Eigen::Lower>() * x;
}

// Preconditioned conjugate gradients on the current system, preconditioned by the factorisation of
// an earlier one: rotations change little from step to step, so a few iterations reach the
// solution. When they do not, the current system is factorised and solved directly, and that
// factorisation preconditions the next steps. In the background (factorise_in_background), a
// solve that took three quarters of max_iterations asks the worker for a fresh factorisation of
// its system (the iterations creep up over tens of steps as the rotations drift from the
// factorised ones, so it arrives before they reach max_iterations), and they go on with the
// older one meanwhile, up to kBackgroundIterationFactor times as far.
Status CorotationalFem::solve_system() {
  iterations_ = 0;
  if (solver_options_.direct || !factorised_) return factorise_and_solve();
  if (background_) take_background_preconditioner();
  const int limit = solver_options_.max_iterations * (background_ ? kBackgroundIterationFactor : 1);
  if (!conjugate_gradients(limit)) return factorise_and_solve();
  if (background_ && 4 * iterations_ >= 3 * solver_options_.max_iterations) background_->request(system_, static_cast<std::uint64_t>(factorisations_));
  return Ok{};
}

// the worker's preconditioner, unless a factorisation in place came since it was asked for (that
// one is newer); a system the worker could not factorise is left to the next solve's fallback
void CorotationalFem::take_background_preconditioner() {
  std::uint64_t asked_at = 0;
  if (background_->take(taken_, asked_at) != BackgroundWorker::Taken::kDone) return;
  if (asked_at != static_cast<std::uint64_t>(factorisations_)) return;
  preconditioner_.swap(taken_);
  ++background_factorisations_;
}

void CorotationalFem::factorise_in_background(bool on) {
  if (!on) {
    background_.reset();
  } else if (!background_) {
    background_ = std::make_unique<BackgroundFactorisation>(system_);
  }
}

CorotationalFem::~CorotationalFem() = default;
CorotationalFem::CorotationalFem(CorotationalFem&&) noexcept = default;
CorotationalFem& CorotationalFem::operator=(CorotationalFem&&) noexcept = default;

Status CorotationalFem::factorise_and_solve() {
  iterations_ = 0;
  solver_->factorize(system_);
  factorised_ = solver_->info() == Eigen::Success;
  if (!factorised_) {
    return Error{"soft::CorotationalFem: the system's factorisation failed (is every part of the body connected?)",
                 ErrorKind::kInvalid};
  }
  ++factorisations_;
  preconditioner_.keep(*solver_);
  increment_ = solver_->solve(rhs_);
  if (!increment_.allFinite()) return Error{"soft::CorotationalFem: the solve gave a non-finite step", ErrorKind::kInvalid};
  return Ok{};
}

bool CorotationalFem::conjugate_gradients(int max_iterations) {
  const double target = solver_options_.relative_residual * rhs_.norm();
  multiply(increment_, product_);
  residual_ = rhs_ - product_;
  preconditioner_.apply(residual_, preconditioned_);
  direction_ = preconditioned_;
  double rz = residual_.dot(preconditioned_);
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    iterations_ = iteration;
    if (!(residual_.norm() > target)) return increment_.allFinite();
    multiply(direction_, product_);
    const double alpha = rz / direction_.dot(product_);
    increment_ += alpha * direction_;
    residual_ -= alpha * product_;
    preconditioner_.apply(residual_, preconditioned_);
    const double rz_next = residual_.dot(preconditioned_);
    direction_ = preconditioned_ + (rz_next / rz) * direction_;
    rz = rz_next;
  }
  iterations_ = max_iterations;
  return !(residual_.norm() > target) && increment_.allFinite();
}

Status CorotationalFem::hold(std::int32_t node, const Eigen::Vector3d& position) {
  if (node < 0 || at(node) >= positions_.size() || !is_fixed(node)) {
    return Error{"soft::CorotationalFem::hold: node " + std::to_string(node) + " is not a fixed node",
                 ErrorKind::kInvalid};
  }
  if (!position.allFinite()) return Error{"soft::CorotationalFem::hold: the position is not finite", ErrorKind::kInvalid};
  held_[at(node)] = position;
  return Ok{};
}

Status CorotationalFem::set_state(std::vector<Eigen::Vector3d> positions, std::vector<Eigen::Vector3d> velocities) {
  const auto fits = [&](const std::vector<Eigen::Vector3d>& v) { return v.size() == positions_.size() && all_finite(v); };
  if (!fits(positions) || !fits(velocities)) {
    return Error{"soft::CorotationalFem::set_state: expected one finite position and velocity per node (" +
                     std::to_string(positions_.size()) + ")",
                 ErrorKind::kInvalid};
  }
  positions_ = std::move(positions);
  velocities_ = std::move(velocities);
  previous_velocities_ = velocities_;
  return Ok{};
}

Status CorotationalFem::check_loads(const std::vector<Eigen::Vector3d>& external_forces) const {
  if (external_forces.size() != positions_.size() || !all_finite(external_forces)) {
    return Error{"soft::CorotationalFem: expected one finite external force per node (" +
                     std::to_string(positions_.size()) + "), got " + std::to_string(external_forces.size()),
                 ErrorKind::kInvalid};
  }
  return Ok{};
}

// moves every node by its increment (free nodes) or to where it is held (fixed nodes); returns the
// largest move [m]
double CorotationalFem::apply_increment(double dt_s) {
  double largest = 0.0;
  for (std::size_t node = 0; node < positions_.size(); ++node) {
    const std::int32_t f = free_index_[node];
    const Eigen::Vector3d move = f < 0 ? Eigen::Vector3d(held_[node] - positions_[node])
                                       : Eigen::Vector3d(increment_.segment<3>(3 * f));
    positions_[node] += move;
    previous_velocities_[node] = dt_s > 0.0 ? velocities_[node] : Eigen::Vector3d::Zero();
    velocities_[node] = dt_s > 0.0 ? Eigen::Vector3d(move / dt_s) : Eigen::Vector3d::Zero();
    largest = std::max(largest, move.norm());
  }
  return largest;
}

Status CorotationalFem::check_contacts(const std::vector<NodeContact>& contacts) const {
  for (const NodeContact& contact : contacts) {
    if (contact.node < 0 || at(contact.node) >= positions_.size() || !contact.force.allFinite() ||
        !contact.stiffness.allFinite()) {
      return Error{"soft::CorotationalFem: a contact names node " + std::to_string(contact.node) + " of " +
                       std::to_string(positions_.size()) + " or is not finite",
                   ErrorKind::kInvalid};
    }
  }
  return Ok{};
}

// backward Euler, M (dx - h v) / h^2 = f_ext + f_el(x) - K' dx - C dx / h with C = alpha M + beta K':
// (M (1/h^2 + alpha/h) + K' (1 + beta/h)) dx = M v / h + f_ext + f_el(x)
Status CorotationalFem::step(double dt_s, const std::vector<Eigen::Vector3d>& external_forces) {
  if (!(dt_s > 0.0) || !std::isfinite(dt_s)) {
    return Error{"soft::CorotationalFem::step: dt_s must be positive and finite", ErrorKind::kInvalid};
  }
  if (auto loads = check_loads(external_forces); !loads) return loads;
  for (std::size_t node = 0; node < positions_.size(); ++node) {
    forces_[node] = external_forces[node] + masses_[node] / dt_s * velocities_[node];
  }
  const double mass_coefficient = 1.0 / (dt_s * dt_s) + material_.mass_damping_per_s / dt_s;
  const double stiffness_coefficient = 1.0 + material_.stiffness_damping_s / dt_s;
  contacts_.clear();
  assemble(mass_coefficient, stiffness_coefficient, forces_, contacts_);
  // the first guess of the iterations: the motion carried on with its last acceleration,
  // dx = h (v + (v - v_previous)); the iterations converge the same from any guess, in fewer
  // iterations from a good one
  for (std::size_t node = 0; node < positions_.size(); ++node) {
    const std::int32_t f = free_index_[node];
    if (f >= 0) increment_.segment<3>(3 * f) = dt_s * (2.0 * velocities_[node] - previous_velocities_[node]);
  }
  if (auto solved = solve_system(); !solved) return solved;
  apply_increment(dt_s);
  return Ok{};
}

Status CorotationalFem::step_response(const std::vector<Eigen::Vector3d>& loads, std::vector<Eigen::Vector3d>& moves) {
  if (!factorised_) {
    return Error{"soft::CorotationalFem::step_response: no step's system is factorised yet", ErrorKind::kInvalid};
  }
  if (auto valid = check_loads(loads); !valid) return valid;
  response_loads_.resize(rhs_.size());
  for (std::size_t node = 0; node < positions_.size(); ++node) {
    const std::int32_t f = free_index_[node];
    if (f >= 0) response_loads_.segment<3>(3 * f) = loads[node];
  }
  preconditioner_.apply(response_loads_, response_);
  moves.resize(positions_.size());
  for (std::size_t node = 0; node < positions_.size(); ++node) {
    const std::int32_t f = free_index_[node];
    moves[node] = f < 0 ? Eigen::Vector3d::Zero() : Eigen::Vector3d(response_.segment<3>(3 * f));
  }
  return Ok{};
}

Result<int> CorotationalFem::solve_static(const std::vector<Eigen::Vector3d>& external_forces, int max_iterations,
                                          double tolerance_m) {
  return solve_static(external_forces, ContactModel{}, max_iterations, tolerance_m);
}

Result<int> CorotationalFem::solve_static(const std::vector<Eigen::Vector3d>& external_forces,
                                          const ContactModel& contacts, int max_iterations, double tolerance_m) {
  if (auto loads = check_loads(external_forces); !loads) return loads.error();
  if (std::none_of(free_index_.begin(), free_index_.end(), [](std::int32_t f) { return f < 0; })) {
    return Error{"soft::CorotationalFem::solve_static: a body with no fixed node has no equilibrium",
                 ErrorKind::kInvalid};
  }
  for (int iteration = 1; iteration <= max_iterations; ++iteration) {
    contacts_.clear();
    if (contacts) contacts(positions_, contacts_);
    if (auto valid = check_contacts(contacts_); !valid) return valid.error();
    assemble(0.0, 1.0, external_forces, contacts_);
    if (auto solved = solve_system(); !solved) return solved.error();
    if (apply_increment(0.0) <= tolerance_m) return iteration;
  }
  return Error{"soft::CorotationalFem::solve_static: no equilibrium within " + std::to_string(max_iterations) +
                   " solves",
               ErrorKind::kInvalid};
}

}  // namespace uh::soft
