#pragma once

#include <algorithm>
#include <cstdint>

#include "uh/core/background_worker.hpp"
#include "uh/soft/block_preconditioner.hpp"

namespace uh::soft {

/// Factorises a copy of a system on a worker thread and hands the preconditioner over, so that the
/// thread that steps a simulation never stops for a factorisation (tens of milliseconds at 5,000
/// tetrahedra, several steps at 200 Hz): it iterates on with the older preconditioner meanwhile.
class BackgroundFactorisation {
 public:
  /// A worker for systems of `pattern`'s sparsity (the values are not read).
  explicit BackgroundFactorisation(const Eigen::SparseMatrix<double>& pattern) : system_(pattern) {
    factorisation_.analyzePattern(system_);
  }

  /// Copies `system`'s values (the pattern's) and starts factorising them, tagged `tag`, unless the
  /// worker is busy (BackgroundWorker::request): then false.
  bool request(const Eigen::SparseMatrix<double>& system, std::uint64_t tag) {
    if (system.nonZeros() != system_.nonZeros()) return false;
    return worker_.request([&] {
      std::copy_n(system.valuePtr(), system.nonZeros(), system_.valuePtr());
      tag_ = tag;
    });
  }

  /// When a factorisation has finished: swaps its preconditioner into `into` and its request's tag
  /// into `tag` (kDone), or, when the system could not be factorised, leaves them (kFailed).
  BackgroundWorker::Taken take(BlockPreconditioner& into, std::uint64_t& tag) {
    return worker_.take([&] {
      into.swap(result_);
      tag = tag_;
    });
  }

 private:
  bool factorise() {
    factorisation_.factorize(system_);
    if (factorisation_.info() != Eigen::Success) return false;
    result_.keep(factorisation_);
    return true;
  }

  Eigen::SparseMatrix<double> system_;
  SystemFactorisation factorisation_;
  BlockPreconditioner result_;
  std::uint64_t tag_ = 0;
  BackgroundWorker worker_{[this] { return factorise(); }};  // last: its thread reads the members above
};

}  // namespace uh::soft
