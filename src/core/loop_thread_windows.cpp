#include <windows.h>
// after windows.h
#include <avrt.h>
#include <timeapi.h>

#include <string>

#include "loop_thread.hpp"

// Windows 10 1803 and later; older systems refuse the flag and get timeBeginPeriod(1) instead
#ifndef CREATE_WAITABLE_TIMER_HIGH_RESOLUTION
#define CREATE_WAITABLE_TIMER_HIGH_RESOLUTION 0x00000002
#endif

namespace uh::detail {
namespace {

std::wstring widen(std::string_view text) {
  std::wstring wide;
  const int n = MultiByteToWideChar(CP_UTF8, 0, text.data(), static_cast<int>(text.size()), nullptr, 0);
  if (n <= 0) return wide;
  wide.resize(static_cast<std::size_t>(n));
  MultiByteToWideChar(CP_UTF8, 0, text.data(), static_cast<int>(text.size()), wide.data(), n);
  return wide;
}

// SetThreadDescription (Windows 10 1607) is looked up, not linked, so that uh.dll still loads
// where it is missing; mingw-w64 10's headers do not declare it either
void set_thread_name(std::string_view name) {
  using SetThreadDescriptionFn = HRESULT(WINAPI*)(HANDLE, PCWSTR);
  HMODULE kernel = GetModuleHandleW(L"kernel32.dll");
  if (kernel == nullptr) return;
  const FARPROC proc = GetProcAddress(kernel, "SetThreadDescription");
  if (proc == nullptr) return;
  // through a generic function pointer type: the cast -Wcast-function-type accepts
  const auto set = reinterpret_cast<SetThreadDescriptionFn>(reinterpret_cast<void (*)()>(proc));
  set(GetCurrentThread(), widen(name).c_str());
}

}  // namespace

struct LoopThread::Os {
  HANDLE timer = nullptr;            // a waitable timer for sleep_until
  bool timer_period_raised = false;  // timeBeginPeriod(1) was called (no high-resolution timer)
  HANDLE mmcss = nullptr;            // the MMCSS task registration, if any
};

LoopThread::LoopThread(std::string_view name) : os_(std::make_unique<Os>()) {
  set_thread_name(name);
  os_->timer =
      CreateWaitableTimerExW(nullptr, nullptr, CREATE_WAITABLE_TIMER_HIGH_RESOLUTION, TIMER_ALL_ACCESS);
  if (os_->timer == nullptr) {
    // a plain timer wakes on the system timer's tick: make that 1 ms for as long as the loop runs
    os_->timer_period_raised = timeBeginPeriod(1) == TIMERR_NOERROR;
    os_->timer = CreateWaitableTimerExW(nullptr, nullptr, 0, TIMER_ALL_ACCESS);
  }
}

LoopThread::~LoopThread() {
  if (os_->mmcss != nullptr) AvRevertMmThreadCharacteristics(os_->mmcss);
  if (os_->timer != nullptr) CloseHandle(os_->timer);
  if (os_->timer_period_raised) timeEndPeriod(1);
}

std::string LoopThread::raise_priority(int level) {
  // MMCSS lifts the thread above other processes' normal threads without administrator rights;
  // where the service is missing or refuses, SetThreadPriority alone still ranks it within ours
  DWORD task_index = 0;
  os_->mmcss = AvSetMmThreadCharacteristicsW(L"Pro Audio", &task_index);
  if (os_->mmcss != nullptr) {
    AvSetMmThreadPriority(os_->mmcss, level >= 80 ? AVRT_PRIORITY_CRITICAL : AVRT_PRIORITY_HIGH);
  }
  const int priority = level >= 80 ? THREAD_PRIORITY_TIME_CRITICAL : THREAD_PRIORITY_HIGHEST;
  if (SetThreadPriority(GetCurrentThread(), priority)) return {};
  return "thread priority " + std::string(level >= 80 ? "TIME_CRITICAL" : "HIGHEST") + " refused (error " +
         std::to_string(GetLastError()) + ")";
}

void LoopThread::sleep_until(std::chrono::steady_clock::time_point t) {
  const auto left =
      std::chrono::duration_cast<std::chrono::nanoseconds>(t - std::chrono::steady_clock::now());
  if (left.count() <= 0) return;
  // a negative due time is relative, in 100 ns units; rounded up, so that the wait never ends early
  LARGE_INTEGER due;
  due.QuadPart = -((left.count() + 99) / 100);
  if (os_->timer != nullptr && SetWaitableTimer(os_->timer, &due, 0, nullptr, nullptr, FALSE)) {
    WaitForSingleObject(os_->timer, INFINITE);
  } else {
    Sleep(static_cast<DWORD>((left.count() + 999'999) / 1'000'000));
  }
}

}  // namespace uh::detail
