extends Node
# ColletteVolume (the paper's ColletteVolume): the pairs whose collisions the game wants to know
# about. add_collision_watcher(a, b) watches a static object against the tool (uh serve computes
# contacts and forces between the tool and watched objects); on_collision(a, b, data) is emitted
# on Godot's main thread: when the contact begins, every frame while it lasts (with that frame's
# newest state) and when it ends. `data`: {"event": "begin" | "contact" | "end", "pairs": int
# (sphere pairs), "volume": float (overlap volume of the latest contact event [m^3]), "force":
# Vector3 [N], "torque": Vector3 [N m] (sent to the device), "time_s": float}.

signal on_collision(a, b, data)

export(NodePath) var haptic_manager
# ColletteStaticMesh nodes watched against the tool (wired in the editor; add_collision_watcher
# adds more from code).
export(Array, NodePath) var watched_objects = []

var _manager = null
var _watchers = []  # [object node, tool node]
var _touching = {}  # object name -> the latest contact event


func _ready():
	_manager = get_node_or_null(haptic_manager) if haptic_manager else null
	if _manager != null:
		_manager.register_volume(self)
	else:
		push_error("ColletteVolume: haptic_manager is not set")
	for path in watched_objects:
		var node = get_node_or_null(path)
		if node != null:
			add_collision_watcher(node)


# Watches `a` (a ColletteStaticMesh) against `b` (the tool's node, or null: the manager's tool);
# the two may come in either order. Call before the session starts.
func add_collision_watcher(a, b = null):
	var object = a
	var tool_node = b
	if b != null and b.is_in_group("collette_static_mesh"):
		object = b
		tool_node = a
	if not object.is_in_group("collette_static_mesh"):
		push_error("ColletteVolume: add_collision_watcher needs a ColletteStaticMesh, got %s" % object.name)
		return
	_watchers.append([object, tool_node])


func watched_object_names(_tool_name):
	var names = []
	for w in _watchers:
		names.append(w[0].object_name())
	return names


func on_contact(event):
	var name = event.get("object", "")
	var watcher = _watcher(name)
	if watcher == null:
		return
	if event["event"] == "begin":
		_touching[name] = event
	else:
		_touching.erase(name)
	emit_signal("on_collision", watcher[0], _tool(watcher), _data(event["event"], event, _manager.state))


func on_state(state):
	for name in _touching.keys():
		var watcher = _watcher(name)
		if watcher != null:
			emit_signal("on_collision", watcher[0], _tool(watcher), _data("contact", _touching[name], state))


func _watcher(name):
	for w in _watchers:
		if w[0].object_name() == name:
			return w
	return null


func _tool(watcher):
	return watcher[1] if watcher[1] != null else _manager.tool_node()


func _data(kind, event, state):
	var f = state.get("force", [0, 0, 0])
	var t = state.get("torque", [0, 0, 0])
	return {
		"event": kind,
		"pairs": state.get("contact_pairs", event.get("pairs", 0)) if kind == "contact" else event.get("pairs", 0),
		"volume": event.get("volume", 0.0),
		"force": Vector3(f[0], f[1], f[2]),
		"torque": Vector3(t[0], t[1], t[2]),
		"time_s": state.get("time_s", event.get("time_s", 0.0)),
	}
