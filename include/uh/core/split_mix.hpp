#pragma once
/// \file
/// SplitMix64 (Steele, Lea and Flood, "Fast splittable pseudorandom number generators", 2014): the
/// project's one seeded generator. Its numbers are the same on every platform and standard library,
/// unlike the std:: distributions, so a seed names one dealt round, one textured surface or one
/// exploration everywhere. Not for cryptography.

#include <cmath>
#include <cstdint>
#include <numbers>

namespace uh::core {

struct SplitMix64 {
  std::uint64_t state = 0;

  std::uint64_t next() {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  /// Uniform in [0, 1) on the 2^-53 grid.
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  /// Uniform in (0, 1]: the grid shifted by half a step, so never 0 (for logarithms). Past 2^52 the
  /// half step rounds to a whole one, so the largest draw gives exactly 1.
  double uniform_open() { return (static_cast<double>(next() >> 11) + 0.5) * 0x1.0p-53; }
  /// An integer in [0, n), n > 0 (the modulo's bias is below n / 2^64).
  int below(int n) { return static_cast<int>(next() % static_cast<std::uint64_t>(n)); }
  /// A standard normal draw (Box-Muller over two open uniforms, so the logarithm is finite), in
  /// place of std::normal_distribution, whose numbers differ between standard libraries.
  double normal() {
    const double r = std::sqrt(-2.0 * std::log(uniform_open()));
    return r * std::cos(2.0 * std::numbers::pi * uniform_open());
  }
};

}  // namespace uh::core
