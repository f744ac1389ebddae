#pragma once
/// \file
/// HaplyDevice: the `haply` driver (Haply Inverse3), through Haply's Inverse Service over
/// WebSocket; the service's reply to each command is the haptic clock.

#include <atomic>
#include <chrono>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "uh/core/result.hpp"
#include "uh/devices/fault_note.hpp"
#include "uh/devices/servo_run.hpp"
#include "uh/devices/shared_library.hpp"
#include "uh/haptico/device_config.hpp"
#include "uh/haptico/servo_clock.hpp"

namespace uh::devices {

/// The service's address when neither the config's `url` nor UH_HAPLY_URL gives one.
inline constexpr const char* kHaplyDefaultUrl = "ws://127.0.0.1:10001";

/// Where the haply driver connects: the config's `url`, else the environment variable
/// UH_HAPLY_URL, else kHaplyDefaultUrl; `origin` says which (for messages and `uh devices`).
LibraryCandidate haply_service_url(const haptico::DeviceConfig& config);

/// A Haply Inverse3 through the Inverse Service, a local program of Haply's that runs the device
/// and speaks JSON over WebSocket (the format in docs/devices.md). On connect the service sends its
/// inventory; after that it answers every command with one state message, so the client's
/// commands pace the device. This device is its own clock (haptico::ClockedDevice): a network
/// thread of the driver's sends the command, waits for the reply and runs the HapticManager's
/// tick on it (state from this reply, force into the next command), never faster than the
/// session's haptic rate.
///
/// Config (tool.device.config): `url` (default UH_HAPLY_URL or ws://127.0.0.1:10001),
/// `device_id` (which Inverse3, e.g. "049D"; default the first in the inventory), `max_force_n`
/// (the force limit; the service reports no rating, so the driver keeps kHaplyDefaultMaxForceN
/// unless told), `workspace` (half extents [m]; not reported by the service, 0 when not given),
/// `timeout_ms` (how long a reply may take before the service counts as stalled, default 100).
///
/// Frame and units: the service's, unchanged: metres, m/s, newtons (see docs/devices.md). The
/// orientation and buttons come from a VerseGrip when the inventory holds one (then 6 DOF sensed),
/// else identity and none. Time: the steady clock when the reply arrived.
///
/// Safety: open() sends nothing. The first command goes out with the first tick, out of the
/// safety stage. A reply that does not come within `timeout_ms`, a closed connection, a message
/// that is not the expected JSON or an error from the service faults the device at once: the tick
/// sees kFault (the HapticManager latches it and commands zero), the driver sends a zero force if
/// the connection still lives, closes it and ends the run; fault_reason() names what failed and
/// the service's message. Re-open to use it again.
///
/// Threads: setup calls from the controlling thread; outside a run read_state() returns the last
/// reply's state and command() is one exchange with the service on the calling thread.
class HaplyDevice final : public haptico::ClockedDevice, private haptico::ServoClock {
 public:
  /// The force limit [N] when the config gives none: a low one, as the service reports no rating.
  static constexpr double kDefaultMaxForceN = 2.0;
  static constexpr double kDefaultTimeoutMs = 100.0;

  /// The driver's factory: checks the config (no I/O; open() connects).
  static Result<std::unique_ptr<haptico::HapticDevice>> create(const haptico::DeviceConfig& config);
  ~HaplyDevice() override;

  haptico::DeviceInfo info() const override { return info_; }
  Status open() override;
  Status close() override;
  haptico::DeviceState read_state() override;
  void command(const haptico::DeviceCommand& cmd) override;
  std::string fault_reason() override { return fault_.text(); }
  haptico::ServoClock& servo_clock() override { return *this; }

  /// The service's address and where it came from.
  const LibraryCandidate& url() const { return url_; }
  /// The device ids of every Inverse3 in the service's inventory (after open()).
  const std::vector<std::string>& inventory() const { return inventory_; }
  /// The opened device's id (after open()).
  const std::string& device_id() const { return info_.serial; }

  struct Connection;  // the WebSocket and its I/O context (haply_device.cpp)

 private:
  struct Selection {
    std::string device_id;  // "" = the first in the inventory
    double max_force_n = kDefaultMaxForceN;
    Vec3 workspace{};
    std::chrono::milliseconds timeout{100};
  };
  HaplyDevice(haptico::DeviceConfig config, Selection selection);

  // ServoClock
  Status start(double rate_hz, FixedRateLoop::Callback tick, FixedRateLoop::ExitCallback on_exit) override;
  void stop() override;
  bool running() const override { return running_.load(std::memory_order_acquire); }
  FixedRateLoopStats stats() const override;
  std::uint64_t missed_deadlines() const override { return run_.missed_deadlines(); }

  Status describe(const std::string& inventory_text);
  // one exchange: sends the pending force, waits for the reply and takes its state; on failure
  // notes the fault (what failed, the service's message) and returns false
  bool exchange();
  // takes the state of this device from a reply; false (fault noted) when it has none
  bool take_reply(const std::string& text);
  void fault(const char* what, const std::string& detail);
  // after a fault or at close: zero force if the connection lives, then the connection closed
  void hang_up();
  void run_loop();
  void join_thread();

  haptico::DeviceConfig config_;
  Selection selection_;
  LibraryCandidate url_;
  std::unique_ptr<Connection> connection_;
  haptico::DeviceInfo info_{};
  std::vector<std::string> inventory_;
  bool has_grip_ = false;
  // the device's thread (the network thread during a run, else the controlling thread)
  haptico::DeviceState state_{};
  Vec3 pending_force_{};
  bool faulted_ = false;
  FaultNote fault_;
  // the run
  std::thread thread_;
  ServoRun run_;
  std::atomic<bool> stop_requested_{false};
  std::atomic<bool> running_{false};
};

}  // namespace uh::devices
