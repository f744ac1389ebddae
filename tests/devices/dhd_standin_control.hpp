#pragma once
// The test side of the stand-in libdhd: its script and observation functions, bound from the same
// file the driver loads (the loader hands out one instance per file, so both see one simulation).

#include <gtest/gtest.h>

#include <array>
#include <string>
#include <vector>

#include "uh/devices/shared_library.hpp"

namespace uh::devices::testing {

class DhdStandin {
 public:
  static const char* path() { return UH_STANDIN_DHD; }

  DhdStandin() {
    auto library = SharedLibrary::load(path());
    EXPECT_TRUE(library) << (library ? "" : library.error().message);
    if (!library) return;
    library_ = std::move(library).value();
    EXPECT_TRUE(library_.bind(reset_, "standin_dhd_reset"));
    EXPECT_TRUE(library_.bind(set_, "standin_dhd_set"));
    EXPECT_TRUE(library_.bind(get_, "standin_dhd_get"));
    EXPECT_TRUE(library_.bind(received_, "standin_dhd_received"));
    reset_();
  }

  /// A global setting (device -1) or one device's.
  void set(const char* key, double value, int device = -1) { EXPECT_EQ(set_(device, key, value), 0) << key; }
  double get(const char* key, int device = 0) const { return get_(device, key); }
  /// Every force the device received while its forces were on.
  std::vector<std::array<double, 3>> received(int device = 0) const {
    const int n = received_(device, nullptr, 0);
    std::vector<double> flat(3 * static_cast<std::size_t>(n));
    received_(device, flat.data(), n);
    std::vector<std::array<double, 3>> out(static_cast<std::size_t>(n));
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = {flat[3 * i], flat[3 * i + 1], flat[3 * i + 2]};
    return out;
  }

 private:
  SharedLibrary library_;
  void (*reset_)() = nullptr;
  int (*set_)(int, const char*, double) = nullptr;
  double (*get_)(int, const char*) = nullptr;
  int (*received_)(int, double*, int) = nullptr;
};

}  // namespace uh::devices::testing
