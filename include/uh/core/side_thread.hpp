#pragma once

#include <condition_variable>
#include <mutex>
#include <thread>
#include <type_traits>

namespace uh {

/// A second thread for one thread's own work, split in two halves run side by side:
/// run_beside(here, there) runs `there` on the side thread and `here` on the caller, and returns
/// once both are done (fork and join, for a simulation step's element pass on a second core).
/// No allocation per call: the callables are passed by reference. One caller at a time.
/// A mutex, a flag and a condition variable, not std::atomic::wait (docs/core.md).
class SideThread {
 public:
  SideThread() : thread_([this] { run(); }) {}
  ~SideThread() {
    {
      const std::lock_guard lock(mutex_);
      stopping_ = true;
    }
    wake_.notify_all();
    thread_.join();
  }
  SideThread(const SideThread&) = delete;
  SideThread& operator=(const SideThread&) = delete;

  template <class Here, class There>
  void run_beside(Here&& here, There&& there) {
    {
      const std::lock_guard lock(mutex_);
      job_ = const_cast<void*>(static_cast<const void*>(&there));
      call_ = [](void* f) { (*static_cast<std::remove_reference_t<There>*>(f))(); };
      done_ = false;
    }
    wake_.notify_all();
    here();
    std::unique_lock lock(mutex_);
    wake_.wait(lock, [this] { return done_; });
  }

 private:
  void run() {
    std::unique_lock lock(mutex_);
    for (;;) {
      wake_.wait(lock, [this] { return stopping_ || job_ != nullptr; });
      if (stopping_) return;
      void* job = job_;
      void (*call)(void*) = call_;
      lock.unlock();
      call(job);
      lock.lock();
      job_ = nullptr;
      done_ = true;
      wake_.notify_all();
    }
  }

  std::mutex mutex_;
  std::condition_variable wake_;  // both ways: a job for the side thread, its end for the caller
  void* job_ = nullptr;
  void (*call_)(void*) = nullptr;
  bool done_ = true;
  bool stopping_ = false;
  std::thread thread_;  // last: started once the members above exist
};

}  // namespace uh
