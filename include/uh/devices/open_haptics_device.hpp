#pragma once
/// \file
/// OpenHapticsDevice: the `openhaptics` driver (3D Systems Touch, Touch X, Phantom), libHD loaded
/// at run time; the HD scheduler owns the servo thread and is the haptic clock.

#include <atomic>
#include <chrono>
#include <memory>
#include <string>
#include <thread>

#include "uh/core/result.hpp"
#include "uh/core/tick_recorder.hpp"
#include "uh/devices/fault_note.hpp"
#include "uh/devices/servo_run.hpp"
#include "uh/devices/shared_library.hpp"
#include "uh/haptico/device_config.hpp"
#include "uh/haptico/servo_clock.hpp"

namespace uh::devices {

namespace hd {
struct Api;
}

/// Where the openhaptics driver looks for libHD (see LibrarySearch).
LibrarySearch open_haptics_library_search();

/// A 3D Systems device through OpenHaptics' HDAPI. HD runs the servo loop on its own scheduler
/// thread, so this device is its own clock (haptico::ClockedDevice): the HapticManager's tick runs
/// inside the scheduler callback, between hdBeginFrame and hdEndFrame, once per servo frame.
///
/// Config (tool.device.config): `library` (path of libHD, see open_haptics_library_search()),
/// `name` (the device's configured name, e.g. "Default Device"; default: HD's default device),
/// `max_force_n` (a lower force limit than the device's nominal one; a larger one is refused).
///
/// Frame: HD's base frame (x right, y up, z toward the user, millimetres, origin at the
/// calibration point) mapped to the convention of the field: x toward the operator (HD z), y right
/// (HD x), z up (HD y), metres, origin at the centre of the device's usable workspace. The 4x4
/// transform is read column-major (translation in elements 12-14). Torques are driven on 6-DOF
/// output devices (HD_OUTPUT_DOF 6), converted from N m to HD's mN m. Time: the steady clock when
/// the frame is read.
///
/// Safety: open() refuses a device whose calibration is not OK (hdCheckCalibration) and turns on
/// HD's own force clamping; HD_FORCE_OUTPUT is enabled at the first non-zero command, which comes
/// out of the HapticManager's safety stage, never at open(). HD's error stack is read after every
/// frame: any error disables HD_FORCE_OUTPUT at once, the device reports kFault from then on with
/// HD's message in fault_reason(); re-open to use it again. close() sends zero, disables forces,
/// stops the scheduler and releases the device.
///
/// Threads: setup calls from the controlling thread; read_state() and command() from the servo
/// tick, or from another thread outside a run, where each becomes one synchronous frame
/// (hdScheduleSynchronous).
class OpenHapticsDevice final : public haptico::ClockedDevice, private haptico::ServoClock {
 public:
  /// The driver's factory: checks the config keys (no I/O; the library is loaded by open()).
  static Result<std::unique_ptr<haptico::HapticDevice>> create(const haptico::DeviceConfig& config);
  ~OpenHapticsDevice() override;

  haptico::DeviceInfo info() const override { return info_; }
  Status open() override;
  Status close() override;
  haptico::DeviceState read_state() override;
  void command(const haptico::DeviceCommand& cmd) override;
  std::string fault_reason() override { return fault_.text(); }
  haptico::ServoClock& servo_clock() override { return *this; }

  /// Model and serial number as the device reports them (after open()).
  const std::string& model() const { return model_; }
  const std::string& serial_number() const { return serial_; }
  /// Where libHD was loaded from (after open()).
  const std::string& library_path() const { return library_.path(); }

 private:
  struct Selection {
    std::string name;          // "" = HD's default device
    double max_force_n = 0.0;  // 0: the device's
    std::chrono::milliseconds stall_limit{250};  // no servo frame for this long ends the run, forces off
  };
  explicit OpenHapticsDevice(haptico::DeviceConfig config, Selection selection);

  // ServoClock
  Status start(double rate_hz, FixedRateLoop::Callback tick, FixedRateLoop::ExitCallback on_exit) override;
  void stop() override;
  bool running() const override { return running_.load(std::memory_order_acquire); }
  FixedRateLoopStats stats() const override;
  std::uint64_t missed_deadlines() const override { return run_.missed_deadlines(); }

  Status describe();
  // the HD error raised by the calls since the last check, as an Error naming `what` ("" = none)
  Status setup_error(const char* what);
  // servo thread: one frame of the run (the scheduler callback)
  static unsigned int servo_frame(void* self);
  unsigned int run_frame();
  // servo thread: reads HD's error stack after a frame; a fault disables forces at once
  void check_frame_errors(const char* where);
  // runs `body` as one synchronous frame in the servo thread (outside a run)
  template <typename Body>
  void in_own_frame(Body&& body);
  void release();
  // the watchdog thread: a scheduler without a frame for kStallLimit ends the run, forces off
  void watch();
  void stop_watchdog();

  haptico::DeviceConfig config_;
  Selection selection_;
  SharedLibrary library_;
  std::unique_ptr<hd::Api> api_;
  unsigned int hhd_ = 0;
  haptico::DeviceInfo info_{};
  std::string model_;
  std::string serial_;
  double centre_mm_[3] = {0.0, 0.0, 0.0};  // centre of the usable workspace, HD frame
  bool open_ = false;
  // the scheduler stopped answering: no more synchronous frames (the watchdog or stop() decides)
  std::atomic<bool> servo_dead_{false};
  // servo thread (and the controlling thread while no frame runs)
  bool forces_on_ = false;
  std::atomic<bool> faulted_{false};  // also claimed by the watchdog: the first to set it notes why
  FaultNote fault_;
  // the run
  ServoRun run_;
  // during a run: a frame's start (steady clock, ns), and the thread that ends a run whose frames stop
  std::atomic<std::int64_t> last_frame_ns_{0};
  std::thread watchdog_;
  std::atomic<bool> watchdog_stop_{false};
  unsigned long handle_ = 0;
  std::atomic<bool> stop_requested_{false};
  std::atomic<bool> running_{false};
};

}  // namespace uh::devices
