#pragma once
/// \file
/// SimRasterDevice ("sim-raster"): the handle sweeps a box region line by line.

#include <vector>

#include "uh/haptico/simulated_device.hpp"

namespace uh::haptico {

/// Options of a SimRasterDevice. Config keys: min, max ("x,y,z" [m]), depth, lines, speed, plus
/// the SimDeviceOptions keys.
struct SimRasterOptions {
  SimDeviceOptions device{};
  Vec3 box_min{-0.02, -0.02, -0.02};  ///< region to sweep, e.g. an object's bounding box [m]
  Vec3 box_max{0.02, 0.02, 0.02};     ///< [m], > box_min component-wise
  double depth = 0.0;                 ///< sweep plane at z = box_max.z - depth [m] (into the top surface)
  int lines = 5;                      ///< number of sweep lines along x, spread evenly over y, >= 1
  double speed = 0.05;                ///< handle speed along the path [m/s], > 0
};

/// Serpentine sweep: along x from min to max, step in y, back along x, ... at constant speed; at
/// the end of the pattern it runs back along the same path (no jump).
class SimRasterDevice final : public ScriptedDevice {
 public:
  explicit SimRasterDevice(const SimRasterOptions& options);
  const SimRasterOptions& options() const { return options_; }
  /// Corner points of the sweep path [m].
  const std::vector<Vec3>& waypoints() const { return waypoints_; }

 private:
  Pose pose_at(double t) const override;
  SimRasterOptions options_;
  std::vector<Vec3> waypoints_;
  std::vector<double> arc_;  // cumulative path length at each waypoint [m]
};

}  // namespace uh::haptico
