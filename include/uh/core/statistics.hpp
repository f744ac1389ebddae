#pragma once
/// \file
/// Small statistics over samples that setup and analysis code share: the median, and an exact
/// rank test for "do these two sets of readings come from one distribution". Not real-time: they
/// copy and sort.

#include <vector>

namespace uh::core {

/// The median of `values` (the mean of the middle two for an even count); 0 when empty.
double median(std::vector<double> values);

/// The two-sided exact p-value of the Wilcoxon-Mann-Whitney rank-sum test: the chance, when `a`
/// and `b` are drawn from one continuous distribution, that their ranks part at least as far as
/// these do. The statistic U counts the pairs (a_i, b_j) with a_i > b_j, a tie counting a half;
/// its null distribution is counted exactly over every way of interleaving the two sets (no
/// normal approximation: readings come a few at a time), a tie rounding towards the larger p.
/// 1 when either set is empty.
double rank_test_p_value(const std::vector<double>& a, const std::vector<double>& b);

}  // namespace uh::core
