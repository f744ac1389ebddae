#include "uh/core/statistics.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace uh::core {

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

namespace {

// counts[u] = how many of the C(m + n, m) interleavings of m a's and n b's have U = u. The largest
// reading is either an a (it beats all n b's: U gains n) or a b (U gains nothing), so
// count(i, j, u) = count(i - 1, j, u - j) + count(i, j - 1, u); the table builds that up row by
// row of i, one flat row of (j, u) cells each. Doubles hold the counts exactly up to 2^53
// interleavings (m + n up to about 55).
std::vector<double> rank_statistic_counts(std::size_t m, std::size_t n) {
  const std::size_t width = m * n + 1;                        // u = 0 .. m n
  std::vector<double> row((n + 1) * width, 0.0), next;        // row[j * width + u] at the current i
  for (std::size_t j = 0; j <= n; ++j) row[j * width] = 1.0;  // no a: U = 0 only
  for (std::size_t i = 1; i <= m; ++i) {
    next.assign((n + 1) * width, 0.0);
    next[0] = 1.0;  // i a's and no b: U = 0
    for (std::size_t j = 1; j <= n; ++j)
      for (std::size_t u = 0; u < width; ++u)
        next[j * width + u] = (u >= j ? row[j * width + u - j] : 0.0) + next[(j - 1) * width + u];
    row.swap(next);
  }
  return {row.begin() + static_cast<std::ptrdiff_t>(n * width), row.end()};
}

}  // namespace

double rank_test_p_value(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.empty() || b.empty()) return 1.0;
  double u = 0.0;
  for (const double x : a)
    for (const double y : b) u += x > y ? 1.0 : x == y ? 0.5 : 0.0;
  const double total_pairs = static_cast<double>(a.size() * b.size());
  // the nearer tail: U this small or (by symmetry) this large
  const double tail = std::ceil(std::min(u, total_pairs - u));
  const std::vector<double> counts = rank_statistic_counts(a.size(), b.size());
  double in_tail = 0.0, all = 0.0;
  for (std::size_t k = 0; k < counts.size(); ++k) {
    all += counts[k];
    if (static_cast<double>(k) <= tail) in_tail += counts[k];
  }
  return std::min(1.0, 2.0 * in_tail / all);
}

}  // namespace uh::core
