#pragma once
/// \file
/// WorkspaceMapping: where the device's workspace sits in the world, and how big it is (a
/// scene's `tool.workspace`).

#include "uh/core/math.hpp"
#include "uh/haptico/device_state.hpp"

namespace uh::scene {

/// Maps device handle states (device base frame, metres) to tool poses in the world (metres), and
/// world wrenches back to device commands. Plain data; every function is real-time safe.
///
/// world_from_tool = world_from_device_base * S(handle pose) * handle_from_tool, where S scales the
/// handle position by `scale` (world metres per device metre) and keeps its orientation.
struct WorkspaceMapping {
  Pose world_from_device_base{};  ///< the device base frame in the world
  double scale = 1.0;             ///< world metres per device metre, > 0
  Pose handle_from_tool{};        ///< the tool's mesh frame relative to the handle

  /// Tool pose in the world for a device state.
  Pose world_from_tool(const haptico::DeviceState& state) const {
    const Pose world_from_handle =
        world_from_device_base * Pose{state.orientation, state.position * scale};
    return world_from_handle * handle_from_tool;
  }
  /// Velocity of the tool frame's origin in the world [m/s].
  Vec3 tool_velocity_world(const haptico::DeviceState& state) const {
    const Vec3 v_handle = rotate(world_from_device_base.rotation, state.linear_velocity * scale);
    const Vec3 w = angular_velocity_world(state);
    const Vec3 offset = rotate(world_from_device_base.rotation * state.orientation, handle_from_tool.position);
    return v_handle + cross(w, offset);
  }
  /// Angular velocity of the tool in the world [rad/s].
  Vec3 angular_velocity_world(const haptico::DeviceState& state) const {
    return rotate(world_from_device_base.rotation, state.angular_velocity);
  }
  /// A world-frame vector (force, torque) in the device base frame.
  Vec3 to_device(const Vec3& v_world) const { return rotate(conjugate(world_from_device_base.rotation), v_world); }
  /// A device-base-frame vector (a force or torque sent to the device) in the world.
  Vec3 to_world(const Vec3& v_device) const { return rotate(world_from_device_base.rotation, v_device); }
};

}  // namespace uh::scene
