#pragma once
/// \file
/// A one-line terminal progress bar for long work (sphere packing, .ist builds). Writes to stderr,
/// redraws at most every 100 ms, and prints nothing when stderr is not a terminal or CI is set
/// (logs stay clean), except the final line.

#include <chrono>
#include <functional>
#include <memory>
#include <string>

namespace uh::cli {

class ProgressBar {
 public:
  explicit ProgressBar(std::string label);
  ~ProgressBar();
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  /// fraction in [0, 1]; values outside are clamped. Call from one thread.
  void update(double fraction);
  /// Draws 100% and ends the line (idempotent).
  void finish();

 private:
  void draw(double fraction);

  std::string label_;
  bool interactive_ = false;
  bool finished_ = false;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
};

/// The bars of work reported in named stages (a session's build: "packing bunny", then "packing
/// stylus"): each new stage name ends the bar before and starts its own. callback() feeds it from a
/// `(stage, fraction)` progress option; finish() (or the destructor) ends the last bar.
class StagedProgress {
 public:
  void update(const std::string& stage, double fraction);
  void finish() { bar_.reset(); }
  /// A `(stage, fraction)` callback into this object, which must outlive the callback's calls.
  std::function<void(const std::string&, double)> callback() {
    return [this](const std::string& stage, double fraction) { update(stage, fraction); };
  }

 private:
  std::unique_ptr<ProgressBar> bar_;
  std::string stage_;
};

}  // namespace uh::cli
