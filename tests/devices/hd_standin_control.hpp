#pragma once
// The test side of the stand-in libHD: its script and observation functions, bound from the same
// file the driver loads (the loader hands out one instance per file, so both see one simulation).

#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "standin_support.hpp"
#include "test_paths.hpp"

namespace uh::devices::testing {

class HdStandin {
 public:
  static const char* path() { return UH_STANDIN_HD; }

  HdStandin() : library_(load_standin(path())) {
    if (!library_.loaded()) return;
    EXPECT_TRUE(library_.bind(reset_, "standin_hd_reset"));
    EXPECT_TRUE(library_.bind(set_, "standin_hd_set"));
    EXPECT_TRUE(library_.bind(get_, "standin_hd_get"));
    EXPECT_TRUE(library_.bind(received_, "standin_hd_received"));
    EXPECT_TRUE(library_.bind(on_scheduler_thread_, "standin_hd_on_scheduler_thread"));
    reset_();
  }

  void set(const char* key, double value) { EXPECT_EQ(set_(key, value), 0) << key; }
  double get(const char* key) const { return get_(key); }
  /// Whether the caller runs on the stand-in's own scheduler thread.
  bool on_scheduler_thread() const { return on_scheduler_thread_() != 0; }
  /// Every force (HD frame) of a frame while HD_FORCE_OUTPUT was on.
  std::vector<std::array<double, 3>> received() const { return received_forces(received_); }

 private:
  SharedLibrary library_;
  void (*reset_)() = nullptr;
  int (*set_)(const char*, double) = nullptr;
  double (*get_)(const char*) = nullptr;
  int (*received_)(double*, int) = nullptr;
  int (*on_scheduler_thread_)() = nullptr;
};

}  // namespace uh::devices::testing
