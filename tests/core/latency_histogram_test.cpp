#include "uh/core/latency_histogram.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <random>
#include <thread>
#include <vector>

TEST(LatencyHistogram, BinsAreContiguousAndTight) {
  // every value lands in a bin whose upper edge is >= the value and at most ~3% above it
  std::uint64_t previous_upper = 0;
  for (int bin = 0; bin < uh::LatencyHistogram::kBinCount; ++bin) {
    const std::uint64_t upper = uh::LatencyHistogram::bin_upper_ns(bin);
    if (bin > 0) {
      ASSERT_GT(upper, previous_upper);
      ASSERT_EQ(uh::LatencyHistogram::bin_of(previous_upper + 1), bin) << "gap before bin " << bin;
    }
    ASSERT_EQ(uh::LatencyHistogram::bin_of(upper), bin);
    previous_upper = upper;
  }
  std::mt19937_64 rng(7);
  for (int i = 0; i < 100000; ++i) {
    const std::uint64_t v = rng() >> (24 + rng() % 40);
    const std::uint64_t upper = uh::LatencyHistogram::bin_upper_ns(uh::LatencyHistogram::bin_of(v));
    ASSERT_GE(upper, v);
    ASSERT_LE(static_cast<double>(upper), static_cast<double>(v) * 1.0313 + 1.0);
  }
}

TEST(LatencyHistogram, PercentilesMatchSortedReference) {
  uh::LatencyHistogram h;
  std::mt19937_64 rng(11);
  std::lognormal_distribution<double> dist(10.0, 1.5);  // around 20 us with a long tail
  std::vector<std::uint64_t> values;
  for (int i = 0; i < 50000; ++i) {
    const auto v = static_cast<std::uint64_t>(dist(rng));
    values.push_back(v);
    h.record(v);
  }
  std::sort(values.begin(), values.end());
  auto reference = [&](double q) {
    const auto rank = static_cast<std::size_t>(std::ceil(q * static_cast<double>(values.size())));
    return static_cast<double>(values[std::max<std::size_t>(rank, 1) - 1]);
  };
  const uh::LatencySummary s = h.summary();
  EXPECT_EQ(s.count, values.size());
  EXPECT_DOUBLE_EQ(s.max_ns, static_cast<double>(values.back()));
  for (const auto& [q, got] : {std::pair{0.5, s.p50_ns}, std::pair{0.99, s.p99_ns}, std::pair{0.999, s.p999_ns}}) {
    const double want = reference(q);
    EXPECT_GE(got, want) << "q=" << q;
    EXPECT_LE(got, want * 1.0313 + 1.0) << "q=" << q;
  }
  double sum = 0.0;
  for (std::uint64_t v : values) sum += static_cast<double>(v);
  EXPECT_NEAR(s.mean_ns, sum / static_cast<double>(values.size()), 1e-6 * s.mean_ns);
}

TEST(LatencyHistogram, EmptyAndReset) {
  uh::LatencyHistogram h;
  EXPECT_EQ(h.summary().count, 0u);
  EXPECT_EQ(h.percentile_ns(0.5), 0.0);
  h.record(1000);
  h.record(~std::uint64_t{0});  // beyond the range: last bin, exact max kept
  EXPECT_EQ(h.count(), 2u);
  EXPECT_EQ(h.max_ns(), ~std::uint64_t{0});
  h.reset();
  EXPECT_EQ(h.summary().count, 0u);
  EXPECT_EQ(h.max_ns(), 0u);
}

TEST(LatencyHistogram, ReadableWhileWritten) {
  uh::LatencyHistogram h;
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (std::uint64_t i = 0; i < 200000; ++i) h.record(i % 5000);
    done.store(true);
  });
  std::uint64_t last = 0;
  bool monotonic = true;
  while (!done.load()) {
    const uh::LatencySummary s = h.summary();
    if (s.count < last) monotonic = false;
    last = s.count;
  }
  writer.join();
  EXPECT_TRUE(monotonic);
  EXPECT_EQ(h.summary().count, 200000u);
  EXPECT_EQ(h.max_ns(), 4999u);
}
