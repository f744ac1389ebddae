#include "uh/core/least_squares.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "uh/core/split_mix.hpp"

namespace uh::core {
namespace {

// the residual sum of squares of coefficients `c` (the reference the fit must not beat)
double residual_of(const std::vector<double>& rows, const std::vector<double>& y, const std::vector<double>& c) {
  double sum = 0.0;
  for (std::size_t i = 0; i < y.size(); ++i) {
    double fitted = 0.0;
    for (std::size_t k = 0; k < c.size(); ++k) fitted += c[k] * rows[i * c.size() + k];
    sum += (y[i] - fitted) * (y[i] - fitted);
  }
  return sum;
}

TEST(LeastSquares, RecoversACubicExactly) {
  std::vector<double> rows, y;
  for (int i = 0; i < 40; ++i) {
    const double u = -1.0 + i / 19.5;
    rows.insert(rows.end(), {1.0, u, u * u, u * u * u});
    y.push_back(0.5 - 2.0 * u + 3.0 * u * u + 0.25 * u * u * u);
  }
  const LeastSquaresFit fit = least_squares(rows, 4, y);
  ASSERT_EQ(fit.coefficients.size(), 4u);
  EXPECT_NEAR(fit.coefficients[0], 0.5, 1e-12);
  EXPECT_NEAR(fit.coefficients[1], -2.0, 1e-12);
  EXPECT_NEAR(fit.coefficients[2], 3.0, 1e-12);
  EXPECT_NEAR(fit.coefficients[3], 0.25, 1e-12);
  EXPECT_NEAR(fit.residual, 0.0, 1e-20);
}

TEST(LeastSquares, ALineMatchesTheClosedFormAndNoNearbyLineFitsBetter) {
  SplitMix64 rng{7};
  std::vector<double> x, y, rows;
  for (int i = 0; i < 200; ++i) {
    x.push_back(rng.uniform() * 10.0);
    y.push_back(1.5 * x.back() - 4.0 + (rng.uniform() - 0.5));
    rows.insert(rows.end(), {1.0, x.back()});
  }
  const LeastSquaresFit fit = least_squares(rows, 2, y);
  ASSERT_EQ(fit.coefficients.size(), 2u);
  double mx = 0.0, my = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    mx += x[i] / static_cast<double>(x.size());
    my += y[i] / static_cast<double>(y.size());
  }
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxy += (x[i] - mx) * (y[i] - my);
    sxx += (x[i] - mx) * (x[i] - mx);
  }
  EXPECT_NEAR(fit.coefficients[1], sxy / sxx, 1e-9);
  EXPECT_NEAR(fit.coefficients[0], my - sxy / sxx * mx, 1e-9);
  EXPECT_NEAR(fit.residual, residual_of(rows, y, fit.coefficients), 1e-9);
  for (int k = 0; k < 2; ++k)
    for (double step : {-1e-3, 1e-3}) {
      std::vector<double> moved = fit.coefficients;
      moved[static_cast<std::size_t>(k)] += step;
      EXPECT_GT(residual_of(rows, y, moved), fit.residual) << "coefficient " << k << " moved by " << step;
    }
}

TEST(LeastSquares, DegenerateColumnsOrMismatchedSizesGiveNoFit) {
  const std::vector<double> same{1.0, 1.0, 2.0, 2.0, 3.0, 3.0};  // two equal columns
  const std::vector<double> y{1.0, 2.0, 3.0};
  EXPECT_TRUE(least_squares(same, 2, y).coefficients.empty());
  EXPECT_TRUE(least_squares(same, 2, std::vector<double>{1.0, 2.0}).coefficients.empty());
  EXPECT_TRUE(least_squares(same, 0, y).coefficients.empty());
  EXPECT_EQ(least_squares(std::vector<double>{1.0, 2.0, 3.0}, 1, y).coefficients.size(), 1u);
}

}  // namespace
}  // namespace uh::core
