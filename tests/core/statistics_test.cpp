#include "uh/core/statistics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

namespace uh::core {
namespace {

TEST(Median, OddEvenAndEmpty) {
  EXPECT_EQ(median({3.0, 1.0, 2.0}), 2.0);
  EXPECT_EQ(median({4.0, 1.0, 3.0, 2.0}), 2.5);
  EXPECT_EQ(median({}), 0.0);
}

// The reference: the permutation test itself. Every way of dealing the pooled readings into a set
// of |a| and a set of |b| is equally likely when both come from one distribution; the p-value is
// the share of deals whose U lies at least as far from its centre as the observed one.
double permutation_p_value(const std::vector<double>& a, const std::vector<double>& b) {
  std::vector<double> pooled = a;
  pooled.insert(pooled.end(), b.begin(), b.end());
  const auto u_of = [&](std::uint32_t in_a) {
    double u = 0.0;
    for (std::size_t i = 0; i < pooled.size(); ++i)
      for (std::size_t j = 0; j < pooled.size(); ++j)
        if ((in_a >> i & 1u) != 0 && (in_a >> j & 1u) == 0)
          u += pooled[i] > pooled[j] ? 1.0 : pooled[i] == pooled[j] ? 0.5 : 0.0;
    return u;
  };
  const double centre = 0.5 * static_cast<double>(a.size() * b.size());
  const double observed = std::fabs(u_of((1u << a.size()) - 1u) - centre);
  double deals = 0.0, as_far = 0.0;
  for (std::uint32_t in_a = 0; in_a < (1u << pooled.size()); ++in_a) {
    if (static_cast<std::size_t>(__builtin_popcount(in_a)) != a.size()) continue;
    deals += 1.0;
    if (std::fabs(u_of(in_a) - centre) >= observed - 1e-12) as_far += 1.0;
  }
  return as_far / deals;
}

TEST(RankTest, CompleteSeparationHasTheSmallestChance) {
  // 3 against 3 all apart: 2 of the C(6, 3) = 20 deals are as far
  EXPECT_DOUBLE_EQ(rank_test_p_value({4.0, 5.0, 6.0}, {1.0, 2.0, 3.0}), 0.1);
  EXPECT_DOUBLE_EQ(rank_test_p_value({1.0, 2.0, 3.0}, {4.0, 5.0, 6.0}), 0.1);
  // 4 against 8: 2 of 495
  EXPECT_DOUBLE_EQ(rank_test_p_value({1, 2, 3, 4}, {5, 6, 7, 8, 9, 10, 11, 12}), 2.0 / 495.0);
}

TEST(RankTest, EmptyOrInterleavedSetsSayNothing) {
  EXPECT_EQ(rank_test_p_value({}, {1.0}), 1.0);
  EXPECT_EQ(rank_test_p_value({1.0}, {}), 1.0);
  EXPECT_EQ(rank_test_p_value({1.0, 4.0}, {2.0, 3.0}), 1.0);  // U = 2, its centre
}

TEST(RankTest, MatchesEveryDealOfThePooledReadings) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (const auto& [m, n] : {std::pair{1, 5}, {3, 4}, {4, 8}, {6, 6}, {5, 9}, {2, 11}}) {
    for (int trial = 0; trial < 12; ++trial) {
      const double shift = 0.4 * trial;  // from like sets to sets well apart
      std::vector<double> a, b;
      for (int i = 0; i < m; ++i) a.push_back(noise(rng) + shift);
      for (int i = 0; i < n; ++i) b.push_back(noise(rng));
      EXPECT_NEAR(rank_test_p_value(a, b), permutation_p_value(a, b), 1e-12) << m << " " << n << " " << trial;
    }
  }
}

TEST(RankTest, TiesRoundTowardsTheLargerChance) {
  // readings to a tenth: ties between the sets
  const std::vector<double> a{1.0, 1.1, 1.1, 1.3, 1.4}, b{0.9, 1.0, 1.1, 1.2, 1.2, 1.4, 1.5};
  EXPECT_GE(rank_test_p_value(a, b), permutation_p_value(a, b) - 1e-12);
}

}  // namespace
}  // namespace uh::core
