#pragma once
// What a FixedRateLoop thread asks of the operating system: its name, a fine timer, a raised
// priority and sleeping until a steady_clock time. One implementation per system:
// loop_thread_posix.cpp (Linux) and loop_thread_windows.cpp.

#include <chrono>
#include <memory>
#include <string>
#include <string_view>

namespace uh::detail {

class LoopThread {
 public:
  /// On the loop thread, before the first tick: names the thread (the OS keeps the first 15
  /// characters on Linux) and makes sleeps wake close to their deadline (Linux: timer slack
  /// 1 ns; Windows: a high-resolution waitable timer, else a 1 ms system timer period).
  explicit LoopThread(std::string_view name);
  /// Undoes what the constructor and raise_priority() changed beyond this thread (Windows:
  /// the system timer period, the MMCSS registration). On the loop thread.
  ~LoopThread();
  LoopThread(const LoopThread&) = delete;
  LoopThread& operator=(const LoopThread&) = delete;

  /// Asks for a real-time priority for this thread; `level` is the 1..99 of
  /// FixedRateLoopOptions::fifo_priority (Linux: SCHED_FIFO at that level; Windows:
  /// THREAD_PRIORITY_TIME_CRITICAL from 80 up, THREAD_PRIORITY_HIGHEST below, and the MMCSS
  /// task "Pro Audio" where the system offers it). Returns an empty string when granted, else why not.
  std::string raise_priority(int level);

  /// Sleeps until `t` (or returns at once if it has passed). Real-time safe: no allocation, no lock.
  void sleep_until(std::chrono::steady_clock::time_point t);

 private:
  struct Os;
  std::unique_ptr<Os> os_;
};

}  // namespace uh::detail
