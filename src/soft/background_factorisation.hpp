#pragma once

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>

#include "uh/soft/block_preconditioner.hpp"

namespace uh::soft {

/// Factorises a copy of a system on its own thread and hands the preconditioner over, so that the
/// thread that steps a simulation never stops for a factorisation (tens of milliseconds at 5,000
/// tetrahedra, several steps at 200 Hz): it iterates on with the older preconditioner meanwhile.
/// One factorisation at a time. The stepping thread's calls never wait: they only try the lock,
/// which the worker holds just to change its state.
/// Built on a mutex and a condition variable (not std::atomic::wait, which loses wake-ups in
/// the Windows build's libstdc++: docs/core.md).
class BackgroundFactorisation {
 public:
  /// A worker for systems of `pattern`'s sparsity (the values are not read). Starts its thread.
  explicit BackgroundFactorisation(const Eigen::SparseMatrix<double>& pattern);
  ~BackgroundFactorisation();
  BackgroundFactorisation(const BackgroundFactorisation&) = delete;
  BackgroundFactorisation& operator=(const BackgroundFactorisation&) = delete;

  /// Copies `system`'s values (the pattern's) and starts factorising them, tagged `tag`, unless a
  /// factorisation is under way or its result not yet taken, or the lock is busy: then false.
  bool request(const Eigen::SparseMatrix<double>& system, std::uint64_t tag);

  enum class Taken { kNothing, kPreconditioner, kFailed };
  /// When a factorisation has finished: swaps its preconditioner into `into` (kPreconditioner) or,
  /// when the system could not be factorised, leaves `into` alone (kFailed); `tag` is the
  /// request's. kNothing while one is under way, none was asked for, or the lock is busy.
  Taken take(BlockPreconditioner& into, std::uint64_t& tag);

  /// Factorisations finished on the worker (taken or not).
  int finished() const;

 private:
  enum class State { kIdle, kRequested, kWorking, kReady, kFailed };
  void run();

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  State state_ = State::kIdle;
  bool stopping_ = false;
  std::uint64_t tag_ = 0;
  int finished_ = 0;
  // written by request() only in kIdle, read by the worker only in kWorking
  Eigen::SparseMatrix<double> system_;
  SystemFactorisation factorisation_;
  BlockPreconditioner result_;
  std::thread thread_;  // last: started once the members above exist
};

}  // namespace uh::soft
