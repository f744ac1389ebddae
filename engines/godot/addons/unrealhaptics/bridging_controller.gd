extends Node
# BridgingController (the paper's BridgingController): bridges the device into the scene. The
# `tool` node follows the device: every frame with a newer haptic state, its global transform
# becomes the tool's pose from the service (move_on_haptic_tick of the HapticManager). Set the
# NodePaths in the editor.

export(NodePath) var haptic_manager
export(NodePath) var tool

var _manager = null
var _tool = null


func _ready():
	_manager = get_node_or_null(haptic_manager) if haptic_manager else null
	_tool = get_node_or_null(tool) if tool else null
	if _manager == null:
		push_error("BridgingController: haptic_manager is not set")
		return
	if _tool != null:
		_manager.register_tool(_tool)
	_manager.connect("move_on_haptic_tick", self, "_on_move")


func _on_move(position, orientation, _buttons):
	if _tool != null:
		_tool.global_transform = Transform(Basis(orientation), position)
