#pragma once
/// \file
/// The hardware drivers, each loading its vendor library (or reaching its service) only when a
/// device is opened, so that every program can offer them without any SDK installed.

#include "uh/core/result.hpp"
#include "uh/haptico/device_registry.hpp"

namespace uh::devices {

/// Registers the hardware drivers in `registry`: `forcedimension` (libdhd),
/// `openhaptics` (libHD). See docs/devices.md.
Status register_hardware_drivers(haptico::DeviceRegistry& registry);

/// A registry with the simulated drivers and the hardware drivers: what `uh run`, the C API and
/// the Python module create devices from.
haptico::DeviceRegistry all_drivers();

}  // namespace uh::devices
