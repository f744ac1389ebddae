#include "progress_bar.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>

namespace uh::cli {

ProgressBar::ProgressBar(std::string label)
    : label_(std::move(label)), start_(std::chrono::steady_clock::now()), last_draw_(start_) {
  const char* ci = std::getenv("CI");
  interactive_ = isatty(STDERR_FILENO) == 1 && (ci == nullptr || std::string(ci).empty());
}

ProgressBar::~ProgressBar() { finish(); }

void ProgressBar::update(double fraction) {
  fraction = std::clamp(fraction, 0.0, 1.0);
  const auto now = std::chrono::steady_clock::now();
  if (!interactive_ || finished_) return;
  if (now - last_draw_ < std::chrono::milliseconds(100) && fraction < 1.0) return;
  last_draw_ = now;
  draw(fraction);
}

void ProgressBar::draw(double fraction) {
  constexpr int kWidth = 30;
  const int filled = static_cast<int>(fraction * kWidth + 0.5);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  std::string bar(static_cast<std::size_t>(filled), '#');
  bar.resize(kWidth, '.');
  std::fprintf(stderr, "\r%s [%s] %3.0f%%  %.1f s", label_.c_str(), bar.c_str(), fraction * 100.0, seconds);
  std::fflush(stderr);
}

void ProgressBar::finish() {
  if (finished_) return;
  finished_ = true;
  if (!interactive_) return;
  draw(1.0);
  std::fputc('\n', stderr);
}

void StagedProgress::update(const std::string& stage, double fraction) {
  if (!bar_ || stage != stage_) {
    bar_.reset();  // ends the stage before with its line, before the next bar draws
    bar_ = std::make_unique<ProgressBar>(stage);
    stage_ = stage;
  }
  bar_->update(fraction);
}

}  // namespace uh::cli
