#include <pthread.h>
#include <sched.h>
#include <sys/prctl.h>
#include <time.h>

#include <cerrno>
#include <string>

#include "loop_thread.hpp"

namespace uh::detail {

struct LoopThread::Os {};

LoopThread::LoopThread(std::string_view name) {
  const std::string short_name(name.substr(0, 15));
  pthread_setname_np(pthread_self(), short_name.c_str());
  // the default timer slack (50 us) would add up to 50 us to every wake-up
  prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
}

LoopThread::~LoopThread() = default;

std::string LoopThread::raise_priority(int level) {
  sched_param param{};
  param.sched_priority = level;
  const int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);
  if (rc == 0) return {};
  return "SCHED_FIFO priority " + std::to_string(level) + " refused (" +
         (rc == EPERM ? std::string("no CAP_SYS_NICE") : "error " + std::to_string(rc)) + ")";
}

// libstdc++'s steady_clock is CLOCK_MONOTONIC, so an absolute clock_nanosleep on that clock
// wakes at the steady_clock time asked for (plus the OS wake-up latency)
void LoopThread::sleep_until(std::chrono::steady_clock::time_point t) {
  const std::int64_t ns = std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count();
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(ns / 1'000'000'000);
  ts.tv_nsec = static_cast<long>(ns % 1'000'000'000);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

}  // namespace uh::detail
