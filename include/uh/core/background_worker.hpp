#pragma once

#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>

namespace uh {

/// One job at a time on a thread of its own, for a thread that must keep its pace (a simulation's
/// steps) and hands slow work (a factorisation, a tree rebuild) over rather than stopping for it.
/// The owner keeps the job's input and output beside the worker: request() fills the input and
/// take() collects the output, each through a callback run under the worker's lock, so the job
/// (which runs without it) never sees them change. The owner's calls never wait: they only try the
/// lock, which the worker holds just to change its state, and give up when it is busy.
/// Built on a mutex and a condition variable, not std::atomic::wait, which loses wake-ups in the
/// Windows build's libstdc++ (docs/core.md).
class BackgroundWorker {
 public:
  enum class Taken { kNothing, kDone, kFailed };

  /// Starts the thread; `job` runs on it once per request and returns whether it succeeded.
  explicit BackgroundWorker(std::function<bool()> job) : job_(std::move(job)), thread_([this] { run(); }) {}
  /// Waits for a job under way to finish (one asked for but not yet started is dropped), then
  /// ends the thread.
  ~BackgroundWorker() {
    {
      const std::lock_guard lock(mutex_);
      stopping_ = true;
    }
    wake_.notify_one();
    thread_.join();
  }
  BackgroundWorker(const BackgroundWorker&) = delete;
  BackgroundWorker& operator=(const BackgroundWorker&) = delete;

  /// When the worker is idle (no job under way, none finished and not yet taken) and its lock
  /// free: runs `fill` (which sets the job's input) and starts the job; true. Otherwise false.
  template <class Fill>
  bool request(Fill&& fill) {
    std::unique_lock lock(mutex_, std::try_to_lock);
    if (!lock.owns_lock() || state_ != State::kIdle) return false;
    fill();
    state_ = State::kRequested;
    lock.unlock();
    wake_.notify_one();
    return true;
  }

  /// When a job has finished and the lock is free: runs `collect` (which takes the job's output)
  /// if it succeeded, and makes the worker idle again; kDone or kFailed. Otherwise kNothing.
  template <class Collect>
  Taken take(Collect&& collect) {
    std::unique_lock lock(mutex_, std::try_to_lock);
    if (!lock.owns_lock() || (state_ != State::kDone && state_ != State::kFailed)) return Taken::kNothing;
    const bool done = state_ == State::kDone;
    if (done) collect();
    state_ = State::kIdle;
    return done ? Taken::kDone : Taken::kFailed;
  }

  /// Whether a job is asked for, under way, or finished and not yet taken. Waits for the lock.
  bool busy() const {
    const std::lock_guard lock(mutex_);
    return state_ != State::kIdle;
  }

 private:
  enum class State { kIdle, kRequested, kWorking, kDone, kFailed };

  void run() {
    std::unique_lock lock(mutex_);
    for (;;) {
      wake_.wait(lock, [this] { return stopping_ || state_ == State::kRequested; });
      if (stopping_) return;
      state_ = State::kWorking;
      lock.unlock();
      const bool done = job_();
      lock.lock();
      state_ = done ? State::kDone : State::kFailed;
    }
  }

  std::function<bool()> job_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  State state_ = State::kIdle;
  bool stopping_ = false;
  std::thread thread_;  // last: started once the members above exist
};

}  // namespace uh
