#include "dhd_api.hpp"

namespace uh::devices::dhd {

Status bind(const SharedLibrary& library, Api& api) {
#define UH_BIND(name) \
  if (Status s = library.bind(api.name, #name); !s) return s
  UH_BIND(dhdGetDeviceCount);
  UH_BIND(dhdOpenID);
  UH_BIND(dhdClose);
  UH_BIND(dhdStop);
  UH_BIND(dhdGetSystemType);
  UH_BIND(dhdGetSystemName);
  UH_BIND(dhdGetSerialNumber);
  UH_BIND(dhdEnableForce);
  UH_BIND(dhdGetPositionAndOrientationFrame);
  UH_BIND(dhdGetLinearVelocity);
  UH_BIND(dhdGetButtonMask);
  UH_BIND(dhdSetForce);
  UH_BIND(dhdGetComFreq);
  UH_BIND(dhdErrorGetLastStr);
  UH_BIND(dhdGetSDKVersion);
#undef UH_BIND
  return Ok{};
}

}  // namespace uh::devices::dhd
