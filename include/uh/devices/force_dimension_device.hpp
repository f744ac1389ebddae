#pragma once
/// \file
/// ForceDimensionDevice: the `forcedimension` driver (omega, delta, sigma; the Novint Falcon through
/// the same SDK), libdhd loaded at run time and polled from the HapticManager's own loop.

#include <memory>
#include <string>

#include "uh/core/event_counter.hpp"
#include "uh/core/result.hpp"
#include "uh/devices/fault_note.hpp"
#include "uh/devices/shared_library.hpp"
#include "uh/haptico/device_config.hpp"
#include "uh/haptico/haptic_device.hpp"

namespace uh::devices {

namespace dhd {
struct Api;
}

/// Where the forcedimension driver looks for libdhd (see LibrarySearch).
LibrarySearch force_dimension_library_search();

/// A Force Dimension device through libdhd (no SDK thread: every call is synchronous I/O on the
/// caller's thread, so the haptic loop is the servo loop).
///
/// Config (tool.device.config): `library` (path of libdhd, see force_dimension_library_search()),
/// `index` (which device, 0-based) or `serial` (its serial number), `max_force_n` (a lower force
/// limit than the device's rated one; a larger one is refused), `workspace` (half extents [m]; only
/// for a model missing from the driver's table, which also needs `max_force_n`).
///
/// Frame: DHD's own, which is the convention of the field: x toward the operator, y right, z up,
/// origin at the workspace centre; metres, newtons, no conversion. Time: the steady clock when
/// read (DHD has no device clock).
///
/// Safety: forces are enabled (dhdEnableForce) at the first command, which comes out of the
/// HapticManager's safety stage, never at open(). A call returning an error faults the device at
/// once: dhdStop (forces off, brakes on), kFault from then on, the vendor's message in
/// fault_reason(); re-open to use it again. DHD_TIMEGUARD (a read too soon: the previous value) is
/// not an error, nor is DHD_MOTOR_SATURATED (the device clipped the force): both are counted.
/// close() sends zero, stops and closes.
class ForceDimensionDevice final : public haptico::HapticDevice {
 public:
  /// The driver's factory: checks the config keys (no I/O; the library is loaded by open()).
  static Result<std::unique_ptr<haptico::HapticDevice>> create(const haptico::DeviceConfig& config);
  ~ForceDimensionDevice() override;

  haptico::DeviceInfo info() const override { return info_; }
  Status open() override;
  Status close() override;
  haptico::DeviceState read_state() override;
  void command(const haptico::DeviceCommand& cmd) override;
  std::string fault_reason() override { return fault_.text(); }

  /// Model name and serial number as the device reports them (after open()).
  const std::string& model() const { return model_; }
  unsigned serial_number() const { return serial_; }
  /// Where libdhd was loaded from (after open()).
  const std::string& library_path() const { return library_.path(); }
  /// The communication rate DHD achieved [Hz] (dhdGetComFreq), sampled by the haptic thread
  /// at the 64th read, every 1024 reads after, and once more by close(). Any thread.
  double com_rate_hz() const { return com_rate_hz_.load(std::memory_order_relaxed); }
  /// Commands the device clipped (DHD_MOTOR_SATURATED). Any thread.
  std::uint64_t saturated_commands() const { return saturated_.load(); }
  /// Reads answered with the previous value (DHD_TIMEGUARD). Any thread.
  std::uint64_t timeguard_reads() const { return timeguard_.load(); }

 private:
  struct Selection {
    int index = 0;
    long serial = -1;          // -1: select by index
    double max_force_n = 0.0;  // 0: the device's
    Vec3 workspace{};          // zero: the device's
  };
  explicit ForceDimensionDevice(haptico::DeviceConfig config, Selection selection);
  Status open_selected();
  Status describe();
  // haptic thread: stops the device and notes why (real-time safe)
  void fault(const char* what);

  haptico::DeviceConfig config_;
  Selection selection_;
  SharedLibrary library_;
  std::unique_ptr<dhd::Api> api_;
  haptico::DeviceInfo info_{};
  std::string model_;
  unsigned serial_ = 0;
  char id_ = -1;  // the DHD device ID while open
  bool open_ = false;
  bool forces_on_ = false;   // haptic thread
  bool faulted_ = false;     // haptic thread
  std::uint64_t reads_ = 0;  // haptic thread
  FaultNote fault_;
  std::atomic<double> com_rate_hz_{0.0};
  EventCounter saturated_;
  EventCounter timeguard_;
};

}  // namespace uh::devices
