#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <array>
#include <cstdint>
#include <vector>

namespace uh::soft {

/// The factorisation of CorotationalFem's systems. Free nodes are numbered in a fill-reducing order
/// of the node graph, so the factor keeps each node's three rows together (3 x 3 blocks) and is
/// factorised in that order as it stands.
using SystemFactorisation =
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::NaturalOrdering<int>>;

/// A single-precision copy of a factorisation L D L^T = A of a system over nodes of three rows each
/// (a block of 3 x 3 per node pair), which solves A y = r approximately: the preconditioner of
/// CorotationalFem's iterations. Floats halve the memory traffic of its two sweeps, which dominate
/// a step; the iterations it preconditions stay in double precision, so only their count depends
/// on its precision. Kept per node column J: the strict lower part of J's diagonal block and the
/// blocks below it, with their node rows.
class BlockPreconditioner {
 public:
  /// Copies the factor: `lower` is L (unit diagonal, column-major, a node's three rows together,
  /// as Eigen's SimplicialLDLT in natural ordering gives it) and `diagonal` is D. Allocates.
  void keep(const Eigen::SparseMatrix<double>& lower, const Eigen::VectorXd& diagonal);
  /// The same from a successful factorisation.
  void keep(const SystemFactorisation& factorised);

  /// result = L^-T D^-1 L^-1 residual. No allocation once kept (result is resized only when its
  /// size differs).
  void apply(const Eigen::VectorXd& residual, Eigen::VectorXd& result);

  bool empty() const { return diagonal_inverse_.size() == 0; }

  /// O(1): the background factorisation hands a finished copy over this way.
  void swap(BlockPreconditioner& other) noexcept;

 private:
  std::vector<std::int32_t> starts_, rows_;
  std::vector<float> blocks_;                  // 9 per block, column-major
  std::vector<std::array<float, 3>> diagonal_;  // L(1,0), L(2,0), L(2,1) of each diagonal block
  Eigen::VectorXf diagonal_inverse_;
  Eigen::VectorXf sweep_;  // the sweeps, in place
};

}  // namespace uh::soft
