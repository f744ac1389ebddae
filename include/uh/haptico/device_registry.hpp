#pragma once
/// \file
/// DeviceRegistry: creates devices by driver name.

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "uh/core/result.hpp"
#include "uh/haptico/device_config.hpp"
#include "uh/haptico/haptic_device.hpp"

namespace uh::haptico {

/// Maps driver names ("sim-line", "sim-hand", a hardware driver...) to factories. A driver is added
/// by registering its factory, without touching haptico. Created devices are not opened yet.
///
/// Threads: setup only (register, then create); not real-time safe, not synchronised.
class DeviceRegistry {
 public:
  /// Builds a device from its config, or returns an Error naming the bad setting.
  using Factory = std::function<Result<std::unique_ptr<HapticDevice>>(const DeviceConfig&)>;

  /// A registry with no drivers.
  DeviceRegistry() = default;
  /// A registry holding the simulated drivers sim-line, sim-circle, sim-raster, sim-replay, sim-hand.
  static DeviceRegistry with_simulated_devices();

  /// Registers `factory` under `name`; an Error if the name is empty or already taken.
  Status register_driver(const std::string& name, Factory factory);
  /// Creates a device; an Error listing the known names when `name` is unknown, or the driver's
  /// own Error when the config is bad.
  Result<std::unique_ptr<HapticDevice>> create(const std::string& name, const DeviceConfig& config = {}) const;

  bool contains(const std::string& name) const { return factories_.count(name) != 0; }
  /// Registered names, sorted.
  std::vector<std::string> names() const;

 private:
  std::map<std::string, Factory> factories_;
};

/// Registers the simulated drivers (see sim_devices.hpp) in `registry`.
Status register_simulated_devices(DeviceRegistry& registry);

}  // namespace uh::haptico
