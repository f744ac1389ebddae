#include "uh/soft/block_preconditioner.hpp"

#include <utility>

namespace uh::soft {
namespace {
constexpr std::size_t at(std::int32_t index) { return static_cast<std::size_t>(index); }
}  // namespace

void BlockPreconditioner::keep(const Eigen::SparseMatrix<double>& lower, const Eigen::VectorXd& diagonal) {
  const auto nodes = static_cast<std::int32_t>(lower.cols() / 3);
  starts_.assign(1, 0);
  rows_.clear();
  blocks_.clear();
  diagonal_.assign(at(nodes), {0.0F, 0.0F, 0.0F});
  std::vector<std::int32_t> block_of_node(at(nodes), -1);  // the block of node row I in this column
  for (std::int32_t column_node = 0; column_node < nodes; ++column_node) {
    for (int c = 0; c < 3; ++c) {
      const std::int32_t column = 3 * column_node + c;
      for (auto k = lower.outerIndexPtr()[column]; k < lower.outerIndexPtr()[column + 1]; ++k) {
        const std::int32_t row = lower.innerIndexPtr()[k];
        const auto value = static_cast<float>(lower.valuePtr()[k]);
        if (row <= column) continue;
        const std::int32_t row_node = row / 3;
        if (row_node == column_node) {
          diagonal_[at(column_node)][at(c + row % 3 - 1)] = value;  // (1,0) -> 0, (2,0) -> 1, (2,1) -> 2
          continue;
        }
        std::int32_t& block = block_of_node[at(row_node)];
        if (block < 0) {
          block = static_cast<std::int32_t>(rows_.size());
          rows_.push_back(row_node);
          blocks_.resize(blocks_.size() + 9, 0.0F);
        }
        blocks_[at(9 * block + 3 * c + row % 3)] = value;
      }
    }
    for (auto b = at(starts_.back()); b < rows_.size(); ++b) block_of_node[at(rows_[b])] = -1;
    starts_.push_back(static_cast<std::int32_t>(rows_.size()));
  }
  diagonal_inverse_ = diagonal.cwiseInverse().cast<float>();
  sweep_.resize(diagonal_inverse_.size());
}

void BlockPreconditioner::keep(const SystemFactorisation& factorised) {
  keep(factorised.matrixL().nestedExpression(), factorised.vectorD());
}

void BlockPreconditioner::apply(const Eigen::VectorXd& residual, Eigen::VectorXd& result) {
  const auto nodes = static_cast<std::int32_t>(diagonal_.size());
  sweep_ = residual.cast<float>();
  float* y = sweep_.data();
  for (std::int32_t j = 0; j < nodes; ++j) {
    const auto& d = diagonal_[at(j)];
    float* yj = y + 3 * j;
    yj[1] -= d[0] * yj[0];
    yj[2] -= d[1] * yj[0] + d[2] * yj[1];
    const float y0 = yj[0], y1 = yj[1], y2 = yj[2];
    for (std::int32_t b = starts_[at(j)]; b < starts_[at(j + 1)]; ++b) {
      const float* l = &blocks_[at(9 * b)];
      float* yi = y + 3 * rows_[at(b)];
      for (int r = 0; r < 3; ++r) yi[r] -= l[r] * y0 + l[3 + r] * y1 + l[6 + r] * y2;
    }
  }
  sweep_.array() *= diagonal_inverse_.array();
  for (std::int32_t j = nodes - 1; j >= 0; --j) {
    float* yj = y + 3 * j;
    float s0 = 0.0F, s1 = 0.0F, s2 = 0.0F;
    for (std::int32_t b = starts_[at(j)]; b < starts_[at(j + 1)]; ++b) {
      const float* l = &blocks_[at(9 * b)];
      const float* yi = y + 3 * rows_[at(b)];
      s0 += l[0] * yi[0] + l[1] * yi[1] + l[2] * yi[2];
      s1 += l[3] * yi[0] + l[4] * yi[1] + l[5] * yi[2];
      s2 += l[6] * yi[0] + l[7] * yi[1] + l[8] * yi[2];
    }
    yj[0] -= s0;
    yj[1] -= s1;
    yj[2] -= s2;
    const auto& d = diagonal_[at(j)];
    yj[1] -= d[2] * yj[2];
    yj[0] -= d[0] * yj[1] + d[1] * yj[2];
  }
  result = sweep_.cast<double>();
}

void BlockPreconditioner::swap(BlockPreconditioner& other) noexcept {
  starts_.swap(other.starts_);
  rows_.swap(other.rows_);
  blocks_.swap(other.blocks_);
  diagonal_.swap(other.diagonal_);
  diagonal_inverse_.swap(other.diagonal_inverse_);
  sweep_.swap(other.sweep_);
}

}  // namespace uh::soft
