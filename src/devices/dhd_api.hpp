#pragma once
// The Force Dimension DHD functions the forcedimension driver uses, declared from the vendor's
// public documentation (no vendor header), bound at run time from libdhd.

#include "uh/core/result.hpp"
#include "uh/devices/shared_library.hpp"

namespace uh::devices::dhd {

// return codes and arguments (documented values)
inline constexpr int kError = -1;          // every function: failure, see dhdErrorGetLastStr
inline constexpr int kTimeGuard = 1;       // DHD_TIMEGUARD: read too soon, the previous value returned
inline constexpr int kMotorSaturated = 2;  // DHD_MOTOR_SATURATED: a force setter clipped the force
inline constexpr unsigned char kOn = 1;    // DHD_ON
inline constexpr unsigned char kOff = 0;   // DHD_OFF

/// Every function as the library exports it (extern "C"; the trailing `char` is the device ID).
struct Api {
  int (*dhdGetDeviceCount)() = nullptr;
  int (*dhdOpenID)(char index) = nullptr;
  int (*dhdClose)(char id) = nullptr;
  int (*dhdStop)(char id) = nullptr;
  int (*dhdGetSystemType)(char id) = nullptr;
  const char* (*dhdGetSystemName)(char id) = nullptr;
  int (*dhdGetSerialNumber)(unsigned short* sn, char id) = nullptr;
  int (*dhdEnableForce)(unsigned char on, char id) = nullptr;
  int (*dhdGetPositionAndOrientationFrame)(double* px, double* py, double* pz, double matrix[3][3],
                                           char id) = nullptr;
  int (*dhdGetLinearVelocity)(double* vx, double* vy, double* vz, char id) = nullptr;
  unsigned int (*dhdGetButtonMask)(char id) = nullptr;
  int (*dhdSetForce)(double fx, double fy, double fz, char id) = nullptr;
  double (*dhdGetComFreq)(char id) = nullptr;
  const char* (*dhdErrorGetLastStr)() = nullptr;
  void (*dhdGetSDKVersion)(int* major, int* minor, int* release, int* revision) = nullptr;
};

/// Binds every function of Api from `library`; an Error naming the first one missing.
Status bind(const SharedLibrary& library, Api& api);

/// The library's message for its last error ("" when it has none).
inline const char* last_error(const Api& api) {
  const char* s = api.dhdErrorGetLastStr != nullptr ? api.dhdErrorGetLastStr() : nullptr;
  return s != nullptr ? s : "";
}

}  // namespace uh::devices::dhd
