#include "uh/devices/hardware_drivers.hpp"

#include "uh/devices/force_dimension_device.hpp"
#include "uh/devices/open_haptics_device.hpp"

namespace uh::devices {

Status register_hardware_drivers(haptico::DeviceRegistry& registry) {
  if (Status s = registry.register_driver("forcedimension", &ForceDimensionDevice::create); !s) return s;
  return registry.register_driver("openhaptics", &OpenHapticsDevice::create);
}

haptico::DeviceRegistry all_drivers() {
  haptico::DeviceRegistry registry = haptico::DeviceRegistry::with_simulated_devices();
  const Status status = register_hardware_drivers(registry);
  (void)status;  // the names differ from the simulated ones: cannot fail
  return registry;
}

}  // namespace uh::devices
