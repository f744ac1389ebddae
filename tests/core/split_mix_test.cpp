#include "uh/core/split_mix.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace uh::core {
namespace {

TEST(SplitMix64, MatchesTheReferenceSequenceOfSeedZero) {
  // the first outputs of the authors' reference implementation (splitmix64.c) seeded with 0
  SplitMix64 g{0};
  EXPECT_EQ(g.next(), 0xE220A8397B1DCDAFull);
  EXPECT_EQ(g.next(), 0x6E789E6AA1B965F4ull);
  EXPECT_EQ(g.next(), 0x06C45D188009454Full);
}

TEST(SplitMix64, UniformsStayInTheirIntervals) {
  SplitMix64 a{7}, b{7};
  for (int i = 0; i < 100000; ++i) {
    const double closed = a.uniform(), open = b.uniform_open();
    ASSERT_GE(closed, 0.0);
    ASSERT_LT(closed, 1.0);
    ASSERT_GT(open, 0.0);
    ASSERT_LE(open, 1.0);
    ASSERT_GE(open - closed, 0.0) << "the same draw, shifted by at most a grid step";
    ASSERT_LE(open - closed, 0x1.0p-53);
  }
}

TEST(SplitMix64, BelowCoversEveryValueEvenly) {
  SplitMix64 g{42};
  std::array<int, 6> counts{};
  const int draws = 60000;
  for (int i = 0; i < draws; ++i) {
    const int v = g.below(6);
    ASSERT_GE(v, 0);
    ASSERT_LT(v, 6);
    ++counts[static_cast<std::size_t>(v)];
  }
  // each face 10,000 expected, standard deviation about 91: 5 sigma
  for (int c : counts) EXPECT_NEAR(c, draws / 6, 460);
}

TEST(SplitMix64, NormalsHaveUnitSpreadAndGaussianTails) {
  SplitMix64 g{7};
  const int draws = 200000;
  double sum = 0.0, sum_sq = 0.0;
  int beyond_two_sigma = 0;
  for (int i = 0; i < draws; ++i) {
    const double x = g.normal();
    ASSERT_TRUE(std::isfinite(x));
    sum += x;
    sum_sq += x * x;
    if (std::abs(x) > 2.0) ++beyond_two_sigma;
  }
  const double mean = sum / draws;
  EXPECT_NEAR(mean, 0.0, 0.012);                       // 5 standard errors (1 / sqrt(draws))
  EXPECT_NEAR(sum_sq / draws - mean * mean, 1.0, 0.016);  // 5 standard errors (sqrt(2 / draws))
  // P(|x| > 2) = 4.55 %, standard deviation of the count about 93: 5 sigma
  EXPECT_NEAR(beyond_two_sigma, 0.0455 * draws, 470);
}

}  // namespace
}  // namespace uh::core
