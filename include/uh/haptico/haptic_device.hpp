#pragma once
/// \file
/// HapticDevice: the narrow interface every device driver implements.

#include <string>

#include "uh/core/result.hpp"
#include "uh/haptico/device_command.hpp"
#include "uh/haptico/device_info.hpp"
#include "uh/haptico/device_state.hpp"

namespace uh::haptico {

/// A haptic device: a handle whose pose is read and to which a force is sent, once per tick.
///
/// Every method is pure virtual on purpose: a driver states what each one does, nothing silently
/// "works" by default. Failing to open gives an Error saying why; there is no dummy device.
///
/// Threads: open(), close() and info() are setup calls (any one thread, not real-time safe).
/// read_state() and command() are called by the haptic thread only, once per tick, in that order;
/// they must be real-time safe in a driver (no allocation, lock, throw or log; report problems
/// through DeviceState::status).
class HapticDevice {
 public:
  virtual ~HapticDevice() = default;

  /// Description of the device; complete after a successful open().
  virtual DeviceInfo info() const = 0;
  /// Connects to the device. Returns an Error a user can act on (which device, what failed).
  virtual Status open() = 0;
  /// Sends zero force and disconnects; idempotent.
  virtual Status close() = 0;
  /// One snapshot of the handle; status is kNotOpen before open() and kFault on a device error.
  virtual DeviceState read_state() = 0;
  /// Renders `cmd` (device frame) until the next command. The caller has already limited it to
  /// info().max_force_n / max_torque_nm; drivers saturate again as the hardware would.
  virtual void command(const DeviceCommand& cmd) = 0;
  /// Why the device last reported kFault, in the driver's and the vendor's words ("" when it has
  /// not, or gave no reason), e.g. "sending the force (dhdSetForce): communication error". Cleared
  /// by open(). Controlling thread, also while the haptic thread runs; not real-time safe.
  virtual std::string fault_reason() = 0;

 protected:
  HapticDevice() = default;
  HapticDevice(const HapticDevice&) = default;
  HapticDevice& operator=(const HapticDevice&) = default;
};

}  // namespace uh::haptico
