#pragma once
/// \file
/// LatencyHistogram: a lock-free log-linear histogram of durations, written by one real-time
/// thread and read by any other thread (after HdrHistogram, reduced to what the loops need).
///
/// Values are nanoseconds. Values below 64 ns have their own bin; above, every power of two is
/// split into 32 bins, so a reported percentile is within about 3% above the true value
/// (percentiles report the upper edge of their bin, clamped to the exact maximum).
/// Range: up to 2^40 ns (about 18 min); larger values land in the last bin.
///
/// Threads: exactly one thread calls record() (real-time safe: no allocation, no lock, a few
/// relaxed atomic operations). Any thread may call snapshot()/percentile_ns()/count()/max_ns()
/// concurrently; while the writer runs, a reading is a consistent-enough approximation (bins are
/// read one by one, so a reading may miss the last few values). reset() must not run concurrently
/// with record().

#include <array>
#include <atomic>
#include <bit>
#include <cstddef>
#include <cstdint>

namespace uh {

/// Percentiles of a LatencyHistogram at one moment, in nanoseconds (0 when empty).
struct LatencySummary {
  std::uint64_t count = 0;  ///< number of recorded values
  double mean_ns = 0.0;     ///< exact mean [ns]
  double p50_ns = 0.0;      ///< median [ns], bin upper edge
  double p99_ns = 0.0;      ///< 99th percentile [ns]
  double p999_ns = 0.0;     ///< 99.9th percentile [ns]
  double max_ns = 0.0;      ///< exact maximum [ns]
};

class LatencyHistogram {
 public:
  static constexpr int kLinearBins = 64;
  static constexpr int kSubBinsLog2 = 5;  ///< 32 bins per power of two
  static constexpr int kMaxExponent = 40;
  static constexpr int kBinCount = kLinearBins + (kMaxExponent - 6 + 1) * (1 << kSubBinsLog2);

  LatencyHistogram() { reset(); }
  LatencyHistogram(const LatencyHistogram&) = delete;
  LatencyHistogram& operator=(const LatencyHistogram&) = delete;

  /// Bin index of a value [ns].
  static constexpr int bin_of(std::uint64_t ns) {
    if (ns < kLinearBins) return static_cast<int>(ns);
    const int exponent = std::bit_width(ns) - 1;  // >= 6
    if (exponent > kMaxExponent) return kBinCount - 1;
    const int sub = static_cast<int>((ns >> (exponent - kSubBinsLog2)) & ((1u << kSubBinsLog2) - 1));
    return kLinearBins + (exponent - 6) * (1 << kSubBinsLog2) + sub;
  }

  /// Largest value [ns] that falls into bin `bin`.
  static constexpr std::uint64_t bin_upper_ns(int bin) {
    if (bin < kLinearBins) return static_cast<std::uint64_t>(bin);
    const int exponent = 6 + (bin - kLinearBins) / (1 << kSubBinsLog2);
    const std::uint64_t sub = static_cast<std::uint64_t>((bin - kLinearBins) % (1 << kSubBinsLog2));
    const std::uint64_t width = std::uint64_t{1} << (exponent - kSubBinsLog2);
    return (std::uint64_t{1} << exponent) + (sub + 1) * width - 1;
  }

  /// Adds one value [ns]. Writer thread only; real-time safe.
  void record(std::uint64_t ns) {
    bins_[static_cast<std::size_t>(bin_of(ns))].fetch_add(1, std::memory_order_relaxed);
    sum_ns_.fetch_add(ns, std::memory_order_relaxed);
    // single writer: a plain load/store pair is enough for the maximum
    if (ns > max_ns_.load(std::memory_order_relaxed)) max_ns_.store(ns, std::memory_order_relaxed);
    count_.fetch_add(1, std::memory_order_release);
  }

  /// Clears all bins. Not concurrently with record().
  void reset() {
    for (auto& b : bins_) b.store(0, std::memory_order_relaxed);
    sum_ns_.store(0, std::memory_order_relaxed);
    max_ns_.store(0, std::memory_order_relaxed);
    count_.store(0, std::memory_order_release);
  }

  [[nodiscard]] std::uint64_t count() const { return count_.load(std::memory_order_acquire); }
  [[nodiscard]] std::uint64_t max_ns() const { return max_ns_.load(std::memory_order_relaxed); }

  /// Value [ns] below or at which a fraction `q` (0..1) of the values lie. Any thread.
  [[nodiscard]] double percentile_ns(double q) const { return percentile_from(read_bins(), q); }

  /// Count, mean and p50/p99/p99.9/max in one pass. Any thread; lock-free.
  [[nodiscard]] LatencySummary summary() const {
    const Bins bins = read_bins();
    LatencySummary s;
    for (std::uint64_t c : bins) s.count += c;
    if (s.count == 0) return s;
    s.mean_ns = static_cast<double>(sum_ns_.load(std::memory_order_relaxed)) / static_cast<double>(s.count);
    s.p50_ns = percentile_from(bins, 0.5);
    s.p99_ns = percentile_from(bins, 0.99);
    s.p999_ns = percentile_from(bins, 0.999);
    s.max_ns = static_cast<double>(max_ns());
    return s;
  }

 private:
  using Bins = std::array<std::uint64_t, kBinCount>;

  Bins read_bins() const {
    Bins out{};
    (void)count_.load(std::memory_order_acquire);
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = bins_[i].load(std::memory_order_relaxed);
    return out;
  }

  double percentile_from(const Bins& bins, double q) const {
    std::uint64_t total = 0;
    for (std::uint64_t c : bins) total += c;
    if (total == 0) return 0.0;
    // rank of the value wanted, 1-based: the smallest value with at least q*total values <= it
    const double wanted = q * static_cast<double>(total);
    std::uint64_t rank = static_cast<std::uint64_t>(wanted);
    if (static_cast<double>(rank) < wanted || rank == 0) ++rank;
    if (rank > total) rank = total;
    std::uint64_t seen = 0;
    const std::uint64_t max = max_ns();
    for (int i = 0; i < kBinCount; ++i) {
      seen += bins[static_cast<std::size_t>(i)];
      if (seen >= rank) {
        const std::uint64_t upper = bin_upper_ns(i);
        return static_cast<double>(upper < max || max == 0 ? upper : max);
      }
    }
    return static_cast<double>(max);
  }

  std::array<std::atomic<std::uint64_t>, kBinCount> bins_;
  std::atomic<std::uint64_t> sum_ns_{0};
  std::atomic<std::uint64_t> max_ns_{0};
  std::atomic<std::uint64_t> count_{0};
};

}  // namespace uh
