#pragma once
/// \file
/// What each driver finds on this machine (`uh devices`): where it looked for its vendor runtime,
/// and the devices it can open.

#include <string>
#include <string_view>
#include <vector>

#include "uh/core/result.hpp"
#include "uh/devices/shared_library.hpp"
#include "uh/haptico/device_config.hpp"
#include "uh/haptico/device_info.hpp"
#include "uh/haptico/device_registry.hpp"

namespace uh::devices {

/// One device a driver can open (plain data).
struct FoundDevice {
  std::string selector{};      ///< what selects it in `uh run --device`, e.g. "forcedimension:0"
  std::string model{};         ///< as the device reports it, e.g. "omega.3"
  std::string serial{};        ///< serial number as text ("" when the device has none)
  haptico::DeviceInfo info{};  ///< as the driver fills it from the device
};

/// One driver's findings (plain data).
struct DriverFindings {
  std::string driver{};                        ///< registry name
  bool simulated = false;                      ///< needs no hardware (nothing to probe)
  std::string runtime{};                       ///< the vendor runtime, e.g. "Force Dimension DHD"
  std::vector<LibraryCandidate> looked_for{};  ///< the places it looked, in order
  std::string loaded_from{};                   ///< the library that loaded ("" when none did)
  std::string error{};                         ///< why nothing was found ("" when devices were)
  std::vector<FoundDevice> devices{};
};

/// Probes every driver of `registry`: each hardware driver loads its runtime the way it would to
/// open a device (no scene config: the environment variable, then the install names), opens each
/// device it finds to read its description, and closes it again; forces are never turned on.
/// Simulated drivers are listed as such. Setup only; takes as long as the vendor's open.
std::vector<DriverFindings> probe_drivers(const haptico::DeviceRegistry& registry);

/// A device named on the command line as DRIVER[:SELECTOR] (`uh run --device`).
struct DeviceChoice {
  std::string driver{};
  /// The selection as config keys: SELECTOR is KEY=VALUE, or a bare VALUE for the driver's usual
  /// key (forcedimension: index, openhaptics: name, haply: device_id).
  haptico::DeviceConfig selection{};
};

/// Parses DRIVER[:SELECTOR]; an Error naming the known drivers or the keys a driver selects by.
Result<DeviceChoice> parse_device_choice(std::string_view text, const haptico::DeviceRegistry& registry);

}  // namespace uh::devices
