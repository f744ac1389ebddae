#include "background_factorisation.hpp"

#include <algorithm>
#include <utility>

namespace uh::soft {

BackgroundFactorisation::BackgroundFactorisation(const Eigen::SparseMatrix<double>& pattern) : system_(pattern) {
  factorisation_.analyzePattern(system_);
  thread_ = std::thread([this] { run(); });
}

BackgroundFactorisation::~BackgroundFactorisation() {
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_one();
  thread_.join();
}

bool BackgroundFactorisation::request(const Eigen::SparseMatrix<double>& system, std::uint64_t tag) {
  std::unique_lock lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock() || state_ != State::kIdle || system.nonZeros() != system_.nonZeros()) return false;
  std::copy_n(system.valuePtr(), system.nonZeros(), system_.valuePtr());
  tag_ = tag;
  state_ = State::kRequested;
  lock.unlock();
  wake_.notify_one();
  return true;
}

BackgroundFactorisation::Taken BackgroundFactorisation::take(BlockPreconditioner& into, std::uint64_t& tag) {
  std::unique_lock lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock()) return Taken::kNothing;
  const State was = state_;
  if (was != State::kReady && was != State::kFailed) return Taken::kNothing;
  if (was == State::kReady) into.swap(result_);
  tag = tag_;
  state_ = State::kIdle;
  return was == State::kReady ? Taken::kPreconditioner : Taken::kFailed;
}

int BackgroundFactorisation::finished() const {
  const std::lock_guard lock(mutex_);
  return finished_;
}

void BackgroundFactorisation::run() {
  std::unique_lock lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return stopping_ || state_ == State::kRequested; });
    if (stopping_) return;
    state_ = State::kWorking;
    lock.unlock();
    factorisation_.factorize(system_);
    const bool factorised = factorisation_.info() == Eigen::Success;
    if (factorised) result_.keep(factorisation_);
    lock.lock();
    ++finished_;
    state_ = factorised ? State::kReady : State::kFailed;
  }
}

}  // namespace uh::soft
