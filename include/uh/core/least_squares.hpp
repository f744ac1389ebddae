#pragma once
/// \file
/// Linear least squares, the one routine of the project: the coefficients c minimising
/// sum_i (y_i - sum_k c_k a_ik)^2 for a design matrix A given row by row. Not real-time: it
/// allocates its result and its scratch.
///
/// It solves the normal equations A^T A c = A^T y by Gauss-Jordan elimination with partial
/// pivoting rather than through Eigen's QR: the fits it serves (a parabola, a cubic, a line, a
/// plane wave over a few slow terms; at most a dozen columns, each scaled by its caller to a size
/// near one) are well conditioned, the routine keeps `uh::core` free of Eigen, and it is the
/// arithmetic the exploration's and the blind player's figures were measured with, to the last bit.

#include <cmath>
#include <cstddef>
#include <span>
#include <utility>
#include <vector>

namespace uh::core {

/// A least-squares fit: the coefficients, one per column, and the residual sum of squares.
/// `coefficients` is empty when the columns are degenerate (a zero pivot) or there are none.
struct LeastSquaresFit {
  std::vector<double> coefficients;
  double residual = 0.0;  ///< sum_i (y_i - fitted_i)^2, in the units of y squared
};

/// Fits `y` (one value per row) by the `columns` columns of `rows` (row-major, rows.size() ==
/// y.size() * columns).
inline LeastSquaresFit least_squares(std::span<const double> rows, std::size_t columns,
                                     std::span<const double> y) {
  LeastSquaresFit out;
  const std::size_t n = columns;
  if (n == 0 || y.empty() || rows.size() != y.size() * n) return out;
  const std::size_t w = n + 1;              // the augmented matrix's width
  std::vector<double> m(n * w, 0.0);        // the normal equations, augmented, row-major
  for (std::size_t i = 0; i < y.size(); ++i) {
    const double* a = rows.data() + i * n;
    for (std::size_t r = 0; r < n; ++r) {
      for (std::size_t c = 0; c < n; ++c) m[r * w + c] += a[r] * a[c];
      m[r * w + n] += a[r] * y[i];
    }
  }
  for (std::size_t col = 0; col < n; ++col) {
    std::size_t pivot = col;
    for (std::size_t r = col + 1; r < n; ++r)
      if (std::fabs(m[r * w + col]) > std::fabs(m[pivot * w + col])) pivot = r;
    for (std::size_t c = 0; c <= n; ++c) std::swap(m[col * w + c], m[pivot * w + c]);
    if (!(std::fabs(m[col * w + col]) > 0.0)) return out;
    for (std::size_t r = 0; r < n; ++r) {
      if (r == col) continue;
      const double q = m[r * w + col] / m[col * w + col];
      for (std::size_t c = 0; c <= n; ++c) m[r * w + c] -= q * m[col * w + c];
    }
  }
  out.coefficients.resize(n);
  for (std::size_t r = 0; r < n; ++r) out.coefficients[r] = m[r * w + n] / m[r * w + r];
  for (std::size_t i = 0; i < y.size(); ++i) {
    double fitted = 0.0;
    for (std::size_t k = 0; k < n; ++k) fitted += out.coefficients[k] * rows[i * n + k];
    out.residual += (y[i] - fitted) * (y[i] - fitted);
  }
  return out;
}

}  // namespace uh::core
