#include "uh/soft/corotational_fem.hpp"

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <string>

namespace uh::soft {
namespace {

// the rotation of F = R S for det F > 0, by Newton's iteration X <- (g X + X^-T / g) / 2 with
// Higham's scaling g: quadratic, a handful of iterations, orthogonal to rounding
bool polar_newton(const Eigen::Matrix3d& deformation, Eigen::Matrix3d& rotation) {
  constexpr int kMaxIterations = 20;
  constexpr double kConverged = 1e-13;
  Eigen::Matrix3d x = deformation;
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    const Eigen::Matrix3d inverse_transpose = x.inverse().transpose();
    const double scale = std::sqrt(inverse_transpose.norm() / x.norm());
    const Eigen::Matrix3d next = 0.5 * (scale * x + inverse_transpose / scale);
    const double change = (next - x).norm();
    x = next;
    if (change < kConverged) {
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
                                                const std::vector<std::int32_t>& fixed) {
  if (auto valid = check_material(material); !valid) return valid.error();
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
  const double lambda = material.young_modulus_pa * material.poisson_ratio /
                        ((1.0 + material.poisson_ratio) * (1.0 - 2.0 * material.poisson_ratio));
  const double mu = material.young_modulus_pa / (2.0 * (1.0 + material.poisson_ratio));
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
    element.rest_inverse = edges.inverse();
    // gradients of the shape functions: rows of the inverse edge matrix, and minus their sum
    std::array<Eigen::Vector3d, 4> g;
    for (int i = 0; i < 3; ++i) g[at(i + 1)] = element.rest_inverse.row(i).transpose();
    g[0] = -(g[1] + g[2] + g[3]);
    // the Hessian of the linear strain energy V (mu eps:eps + lambda/2 tr(eps)^2)
    for (std::size_t a = 0; a < 4; ++a) {
      for (std::size_t b = 0; b < 4; ++b) {
        element.stiffness[a * 4 + b] =
            volume * (lambda * g[a] * g[b].transpose() + mu * g[b] * g[a].transpose() +
                      mu * g[a].dot(g[b]) * Eigen::Matrix3d::Identity());
      }
    }
    for (const std::int32_t n : t) fem.masses_[at(n)] += material.density_kg_m3 * volume / 4.0;
    fem.elements_.push_back(element);
  }
  std::int32_t free_count = 0;
  for (auto& index : fem.free_index_) index = index < 0 ? -1 : free_count++;
  fem.material_ = material;
  fem.positions_ = mesh.nodes;
  fem.held_ = mesh.nodes;
  fem.velocities_.assign(mesh.nodes.size(), Eigen::Vector3d::Zero());
  fem.forces_.assign(mesh.nodes.size(), Eigen::Vector3d::Zero());
  fem.mesh_ = std::move(mesh);
  fem.rhs_.setZero(3 * free_count);
  fem.increment_.setZero(3 * free_count);
  fem.build_pattern();
  return fem;
}

void CorotationalFem::build_pattern() {
  std::vector<Eigen::Triplet<double>> entries;
  for (const auto& element : elements_) {
    for (const std::int32_t a : element.nodes) {
      for (const std::int32_t b : element.nodes) {
        if (free_index_[at(a)] < 0 || free_index_[at(b)] < 0) continue;
        for (int r = 0; r < 3; ++r) {
          for (int c = 0; c < 3; ++c) entries.emplace_back(3 * free_index_[at(b)] + r, 3 * free_index_[at(a)] + c, 0.0);
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
        if (fa < 0 || fb < 0) continue;
        for (int c = 0; c < 3; ++c) block_slots_[(e * 16 + a * 4 + b) * 3 + at(c)] = slot(3 * fb, 3 * fa + c);
      }
    }
  }
  diagonal_slots_.resize(at(static_cast<std::int32_t>(dofs)));
  for (Eigen::Index d = 0; d < dofs; ++d) diagonal_slots_[static_cast<std::size_t>(d)] = slot(d, d);
  solver_ = std::make_unique<Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>>();
  solver_->analyzePattern(system_);
}

// Newton's polar iteration where the element is not inverted (fast, exact); the warm-started turns
// where it is (they never yield a reflection)
void CorotationalFem::update_rotations() {
  constexpr double kLeastVolumeRatio = 1e-3;
  for (auto& element : elements_) {
    const Eigen::Matrix3d deformation = edge_matrix(positions_, element.nodes) * element.rest_inverse;
    if (deformation.determinant() > kLeastVolumeRatio && polar_newton(deformation, element.rotation)) {
      element.quaternion = Eigen::Quaterniond(element.rotation);
      continue;
    }
    rotation_turns_ += extract_rotation(deformation, element.quaternion);
    element.rotation = element.quaternion.toRotationMatrix();
  }
}

// f_a = -R sum_b K_ab (R^T x_b - X_b), added to `forces`
void CorotationalFem::elastic_forces(std::vector<Eigen::Vector3d>& forces) const {
  for (const auto& element : elements_) {
    const Eigen::Matrix3d& rot = element.rotation;
    std::array<Eigen::Vector3d, 4> offset;
    for (std::size_t b = 0; b < 4; ++b) {
      const std::int32_t n = element.nodes[b];
      offset[b] = rot.transpose() * positions_[at(n)] - mesh_.nodes[at(n)];
    }
    for (std::size_t a = 0; a < 4; ++a) {
      Eigen::Vector3d local = Eigen::Vector3d::Zero();
      for (std::size_t b = 0; b < 4; ++b) local += element.stiffness[a * 4 + b] * offset[b];
      forces[at(element.nodes[a])] -= rot * local;
    }
  }
}

// Solves (m M + k K') dx = loads for the free nodes, the fixed ones moving to where they are held,
// and moves the nodes by dx; K' is the stiffness rotated by each element's current rotation
Status CorotationalFem::solve_increment(double mass_coefficient, double stiffness_coefficient,
                                        const std::vector<Eigen::Vector3d>& loads) {
  double* values = system_.valuePtr();
  std::fill(values, values + system_.nonZeros(), 0.0);
  for (std::size_t node = 0; node < positions_.size(); ++node) {
    const std::int32_t f = free_index_[node];
    if (f < 0) continue;
    rhs_.segment<3>(3 * f) = loads[node];
    for (int c = 0; c < 3; ++c) values[diagonal_slots_[at(3 * f + c)]] += mass_coefficient * masses_[node];
  }
  for (std::size_t e = 0; e < elements_.size(); ++e) {
    const Element& element = elements_[e];
    const Eigen::Matrix3d& rot = element.rotation;
    for (std::size_t a = 0; a < 4; ++a) {
      const std::int32_t fa = free_index_[at(element.nodes[a])];
      for (std::size_t b = 0; b < 4; ++b) {
        const std::int32_t fb = free_index_[at(element.nodes[b])];
        if (fa < 0 && fb < 0) continue;
        // block (row b, column a) of the rotated stiffness
        const Eigen::Matrix3d block = stiffness_coefficient * rot * element.stiffness[b * 4 + a] * rot.transpose();
        if (fa < 0) {
          // a held node's prescribed motion loads the free node b
          const std::int32_t held = element.nodes[a];
          rhs_.segment<3>(3 * fb) -= block * (held_[at(held)] - positions_[at(held)]);
          continue;
        }
        if (fb < 0) continue;
        const std::int32_t* slots = &block_slots_[(e * 16 + a * 4 + b) * 3];
        for (int c = 0; c < 3; ++c) {
          for (int r = 0; r < 3; ++r) values[slots[c] + r] += block(r, c);
        }
      }
    }
  }
  return solve_system();
}

// Preconditioned conjugate gradients on the current system, preconditioned by the factorisation of
// an earlier one: rotations change little from step to step, so a few iterations reach the exact
// solution. When they do not, the current system is factorised and solved directly, and that
// factorisation preconditions the next steps.
Status CorotationalFem::solve_system() {
  iterations_ = 0;
  if (factorised_ && conjugate_gradients()) return Ok{};
  solver_->factorize(system_);
  factorised_ = solver_->info() == Eigen::Success;
  if (!factorised_) {
    return Error{"soft::CorotationalFem: the system's factorisation failed (is every part of the body connected?)",
                 ErrorKind::kInvalid};
  }
  ++factorisations_;
  increment_ = solver_->solve(rhs_);
  if (!increment_.allFinite()) return Error{"soft::CorotationalFem: the solve gave a non-finite step", ErrorKind::kInvalid};
  return Ok{};
}

bool CorotationalFem::conjugate_gradients() {
  constexpr int kMaxIterations = 12;
  constexpr double kRelativeResidual = 1e-8;
  const double target = kRelativeResidual * rhs_.norm();
  // the last solve's increment is the first guess: the motion is smooth from step to step
  residual_ = rhs_ - system_ * increment_;
  preconditioned_ = solver_->solve(residual_);
  direction_ = preconditioned_;
  double rz = residual_.dot(preconditioned_);
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    iterations_ = iteration;
    if (!(residual_.norm() > target)) return increment_.allFinite();
    product_.noalias() = system_ * direction_;
    const double alpha = rz / direction_.dot(product_);
    increment_ += alpha * direction_;
    residual_ -= alpha * product_;
    preconditioned_ = solver_->solve(residual_);
    const double rz_next = residual_.dot(preconditioned_);
    direction_ = preconditioned_ + (rz_next / rz) * direction_;
    rz = rz_next;
  }
  iterations_ = kMaxIterations;
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
    velocities_[node] = dt_s > 0.0 ? Eigen::Vector3d(move / dt_s) : Eigen::Vector3d::Zero();
    largest = std::max(largest, move.norm());
  }
  return largest;
}

// backward Euler, M (dx - h v) / h^2 = f_ext + f_el(x) - K' dx - C dx / h with C = alpha M + beta K':
// (M (1/h^2 + alpha/h) + K' (1 + beta/h)) dx = M v / h + f_ext + f_el(x)
Status CorotationalFem::step(double dt_s, const std::vector<Eigen::Vector3d>& external_forces) {
  if (!(dt_s > 0.0) || !std::isfinite(dt_s)) {
    return Error{"soft::CorotationalFem::step: dt_s must be positive and finite", ErrorKind::kInvalid};
  }
  if (auto loads = check_loads(external_forces); !loads) return loads;
  update_rotations();
  for (std::size_t node = 0; node < positions_.size(); ++node) {
    forces_[node] = external_forces[node] + masses_[node] / dt_s * velocities_[node];
  }
  elastic_forces(forces_);
  const double mass_coefficient = 1.0 / (dt_s * dt_s) + material_.mass_damping_per_s / dt_s;
  const double stiffness_coefficient = 1.0 + material_.stiffness_damping_s / dt_s;
  if (auto solved = solve_increment(mass_coefficient, stiffness_coefficient, forces_); !solved) return solved;
  apply_increment(dt_s);
  return Ok{};
}

Result<int> CorotationalFem::solve_static(const std::vector<Eigen::Vector3d>& external_forces, int max_iterations,
                                          double tolerance_m) {
  if (auto loads = check_loads(external_forces); !loads) return loads.error();
  if (std::none_of(free_index_.begin(), free_index_.end(), [](std::int32_t f) { return f < 0; })) {
    return Error{"soft::CorotationalFem::solve_static: a body with no fixed node has no equilibrium",
                 ErrorKind::kInvalid};
  }
  for (int iteration = 1; iteration <= max_iterations; ++iteration) {
    update_rotations();
    forces_ = external_forces;
    elastic_forces(forces_);
    if (auto solved = solve_increment(0.0, 1.0, forces_); !solved) return solved.error();
    if (apply_increment(0.0) <= tolerance_m) return iteration;
  }
  return Error{"soft::CorotationalFem::solve_static: no equilibrium within " + std::to_string(max_iterations) +
                   " solves",
               ErrorKind::kInvalid};
}

}  // namespace uh::soft
