#include "uh/haptico/sim_raster_device.hpp"

#include <algorithm>
#include <cmath>

namespace uh::haptico {

SimRasterDevice::SimRasterDevice(const SimRasterOptions& options)
    : ScriptedDevice("sim-raster", options.device), options_(options) {
  const int lines = std::max(1, options.lines);
  const double z = options.box_max.z - options.depth;
  for (int i = 0; i < lines; ++i) {
    const double y = lines == 1 ? 0.5 * (options.box_min.y + options.box_max.y)
                                : options.box_min.y + (options.box_max.y - options.box_min.y) * i / (lines - 1);
    const bool forward = i % 2 == 0;
    waypoints_.push_back({forward ? options.box_min.x : options.box_max.x, y, z});
    waypoints_.push_back({forward ? options.box_max.x : options.box_min.x, y, z});
  }
  arc_.push_back(0.0);
  for (std::size_t i = 1; i < waypoints_.size(); ++i) arc_.push_back(arc_.back() + norm(waypoints_[i] - waypoints_[i - 1]));
}

Pose SimRasterDevice::pose_at(double t) const {
  const double total = arc_.back();
  if (!(total > 0.0)) return Pose{Quat{}, waypoints_.front()};
  // ping-pong along the path so that the motion never jumps
  const double phase = std::fmod(options_.speed * t, 2.0 * total);
  const double s = phase <= total ? phase : 2.0 * total - phase;
  const auto it = std::upper_bound(arc_.begin(), arc_.end(), s);
  const std::size_t i = std::min<std::size_t>(static_cast<std::size_t>(it - arc_.begin()), arc_.size() - 1);
  const std::size_t a = i - 1;
  const double len = arc_[i] - arc_[a];
  const double u = len > 0.0 ? (s - arc_[a]) / len : 0.0;
  return Pose{Quat{}, waypoints_[a] + u * (waypoints_[i] - waypoints_[a])};
}

}  // namespace uh::haptico
