#include "uh/devices/hardware_drivers.hpp"

#include "uh/devices/force_dimension_device.hpp"
#ifdef UH_DEVICES_HAPLY
#include "uh/devices/haply_device.hpp"
#endif
#include "uh/devices/open_haptics_device.hpp"

namespace uh::devices {

Status register_hardware_drivers(haptico::DeviceRegistry& registry) {
  if (Status s = registry.register_driver("forcedimension", &ForceDimensionDevice::create); !s) return s;
#ifdef UH_DEVICES_HAPLY  // not in the Windows build (src/devices/CMakeLists.txt)
  if (Status s = registry.register_driver("haply", &HaplyDevice::create); !s) return s;
#endif
  return registry.register_driver("openhaptics", &OpenHapticsDevice::create);
}

haptico::DeviceRegistry all_drivers() {
  haptico::DeviceRegistry registry = haptico::DeviceRegistry::with_simulated_devices();
  const Status status = register_hardware_drivers(registry);
  (void)status;  // the names differ from the simulated ones: cannot fail
  return registry;
}

}  // namespace uh::devices
