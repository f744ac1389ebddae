#pragma once
/// \file
/// FaultNote: why a device faulted, handed from the thread that saw it to the controlling thread.

#include <array>
#include <string>

#include "uh/core/latest_value.hpp"

namespace uh::devices {

/// A fault's text in a fixed buffer (trivially copyable, for LatestValue).
struct FaultText {
  std::array<char, 256> chars{};
};

/// The first fault a driver saw since clear(), as text (what failed and the vendor's message),
/// kept in a fixed buffer so that the haptic thread records it without allocating.
///
/// Threads: note() from the one thread that runs the device (the haptic thread, or a vendor's servo
/// thread), real-time safe; text() from the controlling thread; clear() from the controlling
/// thread while no thread runs the device.
class FaultNote {
 public:
  /// Records "`what`: `detail`" (truncated to 255 characters) unless a fault is already noted.
  void note(const char* what, const char* detail);
  /// The noted fault, or "" when none.
  std::string text();
  void clear();
  /// Whether a fault was noted since clear(); the noting thread.
  bool noted() const { return noted_; }

 private:
  using Text = FaultText;
  LatestValue<Text> handoff_;
  Text last_{};
  bool noted_ = false;
};

}  // namespace uh::devices
