#pragma once
/// \file
/// BridgingController: moves the tool object in the collision world with the device (the paper's
/// BridgingController, section 3.2.5).

#include "uh/collette/collision_world.hpp"
#include "uh/controllers/workspace_mapping.hpp"
#include "uh/core/delegator.hpp"
#include "uh/controllers/force_controller.hpp"
#include "uh/haptico/haptic_manager.hpp"

namespace uh::controllers {

/// Binds to MoveOnHapticTick and writes the tool's pose into the collision world every haptic tick
/// (through the world's lock-free pose handoff). When the ForceController renders through a virtual
/// coupling, the tool is the coupling's simulated proxy instead of the handle itself. With a
/// ToolProxy (the god-object), the handle's pose becomes the proxy's target and the proxy moves
/// the tool on the collision thread.
///
/// Threads: construct and bind() on the controlling thread before the haptic thread starts;
/// on_move() runs on the haptic thread (real-time safe). The haptic thread is the single writer of
/// the tool's pose.
class BridgingController {
 public:
  /// `force_controller` may be null; when given it must outlive this controller, and its coupling
  /// (if any) decides where the tool is.
  BridgingController(collette::CollisionWorld& world, collette::ObjectId tool, const WorkspaceMapping& mapping,
                     const ForceController* force_controller = nullptr, ToolProxy* proxy = nullptr)
      : world_(&world), tool_(tool), mapping_(mapping), force_controller_(force_controller), proxy_(proxy) {}

  /// Connects on_move to the manager's MoveOnHapticTick; the connection ends with this object.
  void bind(haptico::HapticManager& manager) {
    connection_ = manager.move_on_haptic_tick().connect<&BridgingController::on_move>(*this);
  }

  /// MoveOnHapticTick handler. Haptic thread; real-time safe.
  void on_move(const haptico::DeviceState& state) {
    if (state.status != haptico::DeviceStatus::kOk) return;
    if (proxy_ != nullptr) {
      // the proxy moves the tool in the world (collision thread); the handle only says where to
      last_pose_ = mapping_.world_from_tool(state);
      proxy_->set_target(last_pose_);
      return;
    }
    const bool coupled = force_controller_ != nullptr && force_controller_->coupling() != nullptr &&
                         force_controller_->proxy_placed();
    last_pose_ = coupled ? force_controller_->coupling()->world_from_proxy() : mapping_.world_from_tool(state);
    world_->set_pose(tool_, last_pose_);
  }

  /// The pose written last, or with a ToolProxy the handle's pose given to it last (haptic thread only).
  const Pose& last_pose() const { return last_pose_; }
  const WorkspaceMapping& mapping() const { return mapping_; }

 private:
  collette::CollisionWorld* world_;
  collette::ObjectId tool_;
  WorkspaceMapping mapping_;
  const ForceController* force_controller_;
  ToolProxy* proxy_;
  Pose last_pose_{};
  ScopedConnection connection_;
};

}  // namespace uh::controllers
