#pragma once
// A loopback stand-in of Haply's Inverse Service (test-only, never a driver): a WebSocket server on
// 127.0.0.1 (an ephemeral port) on its own thread, speaking the format of docs/devices.md. It sends
// the inventory on connect and one state message per command. Its Inverse3 is a scripted cursor
// plus a mass on a spring moved by the commanded force; it fails on demand.

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "uh/core/math.hpp"

namespace uh::devices::testing {

/// How the stand-in fails, after HaplyStandinScript::fault_after replies to commands.
enum class HaplyFault {
  kNone,
  kDrop,     ///< closes the connection without a WebSocket close
  kSilent,   ///< keeps reading commands and answers none
  kError,    ///< answers with {"error": {"message": error_text}}
  kBadJson,  ///< answers with a message that is not JSON
};

struct HaplyStandinScript {
  std::string device_id = "049D";
  bool with_grip = false;   ///< a VerseGrip in the inventory and the states
  Quat grip_orientation{};  ///< the grip's orientation (sent as w, x, y, z)
  bool button_b = false;    ///< the grip's button b pressed
  /// The cursor's scripted path [m]: from `start` to `end` over `motion_replies` replies (then it
  /// stays at `end`, or goes back and forth when `bounce`); the mass-spring's displacement adds to it.
  Vec3 start{};
  Vec3 end{};
  int motion_replies = 0;
  bool bounce = false;
  double mass_kg = 0.2;
  double stiffness_n_per_m = 400.0;
  double damping_n_s_per_m = 8.0;
  double dt_s = 0.001;  ///< simulated time per command
  HaplyFault fault = HaplyFault::kNone;
  int fault_after = 0;  ///< replies before the fault (in each connection)
  std::string error_text = "Inverse3 049D: the motors are too hot";
  /// Answer with "values" instead of "vector" expected in commands: an older service.
  bool legacy_force_key = false;
};

class HaplyStandinService {
 public:
  explicit HaplyStandinService(HaplyStandinScript script = {});
  ~HaplyStandinService();
  HaplyStandinService(const HaplyStandinService&) = delete;
  HaplyStandinService& operator=(const HaplyStandinService&) = delete;

  int port() const { return port_; }
  std::string url() const { return "ws://127.0.0.1:" + std::to_string(port_); }

  /// Replaces the script (the next connection starts from it; a live one uses it from its next
  /// message).
  void set_script(const HaplyStandinScript& script);
  /// Every force commanded so far, in order [N] (a command without a readable force is NaN).
  std::vector<Vec3> received() const;
  /// Connections accepted so far.
  int connections() const;
  /// Replies with a state sent so far (not the inventories).
  std::int64_t replies() const;
  /// The cursor position of reply `k` of a connection with no force ever commanded (the script).
  Vec3 scripted_position(std::int64_t k) const;
  /// The position sent in the last state message.
  Vec3 last_position() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
  int port_ = 0;
};

}  // namespace uh::devices::testing
