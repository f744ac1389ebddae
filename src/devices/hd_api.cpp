#include "hd_api.hpp"

namespace uh::devices::hd {

Status bind(const SharedLibrary& library, Api& api) {
#define UH_BIND(name) \
  if (Status s = library.bind(api.name, #name); !s) return s
  UH_BIND(hdInitDevice);
  UH_BIND(hdDisableDevice);
  UH_BIND(hdMakeCurrentDevice);
  UH_BIND(hdGetError);
  UH_BIND(hdGetErrorString);
  UH_BIND(hdEnable);
  UH_BIND(hdDisable);
  UH_BIND(hdStartScheduler);
  UH_BIND(hdStopScheduler);
  UH_BIND(hdSetSchedulerRate);
  UH_BIND(hdScheduleAsynchronous);
  UH_BIND(hdScheduleSynchronous);
  UH_BIND(hdUnschedule);
  UH_BIND(hdWaitForCompletion);
  UH_BIND(hdBeginFrame);
  UH_BIND(hdEndFrame);
  UH_BIND(hdGetDoublev);
  UH_BIND(hdGetIntegerv);
  UH_BIND(hdSetDoublev);
  UH_BIND(hdGetString);
  UH_BIND(hdCheckCalibration);
#undef UH_BIND
  return Ok{};
}

}  // namespace uh::devices::hd
