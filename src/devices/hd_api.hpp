#pragma once
// The OpenHaptics HDAPI functions and constants the openhaptics driver uses, declared from the
// vendor's public documentation (no vendor header), bound at run time from libHD.

#include "uh/core/result.hpp"
#include "uh/devices/shared_library.hpp"

namespace uh::devices::hd {

using HHD = unsigned int;
using HDenum = unsigned int;
using HDerror = unsigned int;
using HDSchedulerHandle = unsigned long;
using HDCallbackCode = unsigned int;
using HDboolean = unsigned char;

struct HDErrorInfo {
  HDerror errorCode;
  int internalErrorCode;
  HHD hHD;
};

// documented values
inline constexpr HHD kInvalidHandle = 0xFFFFFFFFu;  // HD_INVALID_HANDLE
inline constexpr HDerror kSuccess = 0;              // HD_SUCCESS
inline constexpr HDCallbackCode kCallbackDone = 0;  // HD_CALLBACK_DONE
inline constexpr HDCallbackCode kCallbackContinue = 1;
inline constexpr unsigned short kMaxSchedulerPriority = 0xFFFF;  // HD_MAX_SCHEDULER_PRIORITY
inline constexpr HDenum kWaitCheckStatus = 0;                    // HD_WAIT_CHECK_STATUS
inline constexpr HDenum kCalibrationOk = 0x5000;

inline constexpr HDenum kCurrentButtons = 0x2000;
inline constexpr HDenum kCurrentPosition = 0x2050;            // mm
inline constexpr HDenum kCurrentVelocity = 0x2051;            // mm/s
inline constexpr HDenum kCurrentTransform = 0x2052;           // column-major 4x4, translation mm
inline constexpr HDenum kCurrentAngularVelocity = 0x2053;     // rad/s
inline constexpr HDenum kCurrentForce = 0x2700;               // N
inline constexpr HDenum kCurrentTorque = 0x2701;              // mN m
inline constexpr HDenum kNominalMaxForce = 0x2603;            // N
inline constexpr HDenum kNominalMaxTorqueForce = 0x2622;      // mN m
inline constexpr HDenum kDeviceModelType = 0x2501;            // string
inline constexpr HDenum kDeviceSerialNumber = 0x2504;         // string
inline constexpr HDenum kOutputDof = 0x2508;                  // 3 or 6
inline constexpr HDenum kUsableWorkspaceDimensions = 0x2551;  // min xyz, max xyz [mm]
inline constexpr HDenum kForceOutput = 0x4000;
inline constexpr HDenum kMaxForceClamping = 0x4001;

/// Every function as the library exports it.
struct Api {
  HHD (*hdInitDevice)(const char* name) = nullptr;
  void (*hdDisableDevice)(HHD) = nullptr;
  void (*hdMakeCurrentDevice)(HHD) = nullptr;
  HDErrorInfo (*hdGetError)() = nullptr;
  const char* (*hdGetErrorString)(HDerror) = nullptr;
  void (*hdEnable)(HDenum) = nullptr;
  void (*hdDisable)(HDenum) = nullptr;
  void (*hdStartScheduler)() = nullptr;
  void (*hdStopScheduler)() = nullptr;
  void (*hdSetSchedulerRate)(unsigned long hz) = nullptr;
  HDSchedulerHandle (*hdScheduleAsynchronous)(HDCallbackCode (*cb)(void*), void* data,
                                              unsigned short priority) = nullptr;
  void (*hdScheduleSynchronous)(HDCallbackCode (*cb)(void*), void* data, unsigned short priority) = nullptr;
  void (*hdUnschedule)(HDSchedulerHandle) = nullptr;
  HDboolean (*hdWaitForCompletion)(HDSchedulerHandle, HDenum param) = nullptr;
  void (*hdBeginFrame)(HHD) = nullptr;
  void (*hdEndFrame)(HHD) = nullptr;
  void (*hdGetDoublev)(HDenum, double* out) = nullptr;
  void (*hdGetIntegerv)(HDenum, int* out) = nullptr;
  void (*hdSetDoublev)(HDenum, const double* in) = nullptr;
  const char* (*hdGetString)(HDenum) = nullptr;
  HDenum (*hdCheckCalibration)() = nullptr;
};

/// Binds every function of Api from `library`; an Error naming the first one missing.
Status bind(const SharedLibrary& library, Api& api);

/// The library's text for `code` ("" when it has none).
inline const char* error_text(const Api& api, HDerror code) {
  const char* s = api.hdGetErrorString != nullptr ? api.hdGetErrorString(code) : nullptr;
  return s != nullptr ? s : "";
}

}  // namespace uh::devices::hd
