#pragma once
/// \file
/// SimReplayDevice ("sim-replay"): replays a recorded trajectory.

#include <istream>
#include <memory>
#include <string>
#include <vector>

#include "uh/core/result.hpp"
#include "uh/haptico/simulated_device.hpp"

namespace uh::haptico {

/// One recorded sample.
struct TrajectorySample {
  double time_s = 0.0;  ///< [s]
  Pose pose{};          ///< [m], unit quaternion
  std::uint32_t buttons = 0;  ///< button bit mask from this sample on (optional column `buttons`)
};

/// Options of a SimReplayDevice. Config keys: file (required), loop (0/1), plus the
/// SimDeviceOptions keys.
struct SimReplayOptions {
  SimDeviceOptions device{};
  bool loop = false;  ///< start over after the last sample; otherwise hold the last pose
};

/// Plays back a trajectory: position interpolated linearly, orientation by normalised linear
/// interpolation (shortest way), time measured from the first sample.
class SimReplayDevice final : public ScriptedDevice {
 public:
  /// Reads a CSV trajectory "time_s,x,y,z,qw,qx,qy,qz" (one optional header line, '#' comments and
  /// blank lines allowed, times strictly increasing, at least one sample). Errors name the file
  /// and line and say what was expected.
  static Result<std::vector<TrajectorySample>> parse_csv(std::istream& in, const std::string& source_name);
  static Result<std::vector<TrajectorySample>> load_csv(const std::string& path);

  /// Setup only; `samples` must be non-empty with increasing times (as parse_csv guarantees).
  SimReplayDevice(std::vector<TrajectorySample> samples, const SimReplayOptions& options);
  const std::vector<TrajectorySample>& samples() const { return samples_; }
  /// Time span of the recording [s].
  double duration_s() const { return samples_.back().time_s - samples_.front().time_s; }

 private:
  Pose pose_at(double t) const override;
  std::uint32_t buttons_at(double t) const override;
  /// The recording's own time at device time t (wrapped when looping).
  double recording_time(double t) const;
  std::vector<TrajectorySample> samples_;
  SimReplayOptions options_;
};

}  // namespace uh::haptico
