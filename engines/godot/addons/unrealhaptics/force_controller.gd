extends Node
# ForceController (the paper's ForceController): applies the ForceComponent's settings to the
# tool and reports the force rendered. The force itself is computed in uh serve on its haptic
# thread (1 kHz); force_on_haptic_tick(force, torque) is emitted on Godot's main thread every frame
# with a newer state: what the device was sent in the newest tick (world frame, N and N m).

signal force_on_haptic_tick(force, torque)

export(NodePath) var haptic_manager
export(NodePath) var force_component

var _manager = null


func _ready():
	_manager = get_node_or_null(haptic_manager) if haptic_manager else null
	var component = get_node_or_null(force_component) if force_component else null
	if _manager == null:
		push_error("ForceController: haptic_manager is not set")
		return
	if component != null:
		_manager.register_force_component(component)
	_manager.connect("move_on_haptic_tick", self, "_on_tick")


func _on_tick(_position, _orientation, _buttons):
	emit_signal("force_on_haptic_tick", _manager.force, _manager.torque)
