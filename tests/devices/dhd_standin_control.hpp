#pragma once
// The test side of the stand-in libdhd: its script and observation functions, bound from the same
// file the driver loads (the loader hands out one instance per file, so both see one simulation).

#include <gtest/gtest.h>

#include <array>
#include <string>
#include <vector>

#include "standin_support.hpp"
#include "test_paths.hpp"

namespace uh::devices::testing {

class DhdStandin {
 public:
  static const char* path() { return UH_STANDIN_DHD; }

  DhdStandin() : library_(load_standin(path())) {
    if (!library_.loaded()) return;
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
    return received_forces([&](double* out, int max) { return received_(device, out, max); });
  }

 private:
  SharedLibrary library_;
  void (*reset_)() = nullptr;
  int (*set_)(int, const char*, double) = nullptr;
  double (*get_)(int, const char*) = nullptr;
  int (*received_)(int, double*, int) = nullptr;
};

}  // namespace uh::devices::testing
