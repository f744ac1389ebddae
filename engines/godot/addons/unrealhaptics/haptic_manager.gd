extends Node
# HapticManager (the paper's HapticManager actor): owns the connection to `uh serve`, which runs
# the haptic and collision threads (GDScript cannot host a 1 kHz loop). On start it connects to the
# service on host:port, or starts `uh serve` as a child process when none answers there; sends
# the Godot scene (the ColletteStaticMesh nodes' meshes inline, their poses, the ForceComponent's
# force settings, the device, the rates, the ColletteVolumes' watchers), starts the session and
# subscribes to its state at the engine's frame rate. Every frame with a newer state it emits
# move_on_haptic_tick; contact events go to the ColletteVolumes. Stopping (stop_haptics(), or the
# node leaving the tree) stops the session (the service sends zero force and joins its threads)
# and stops the child service if this node started it.
#
# Threads: everything here runs on Godot's main thread; the haptic thread is in the service.
# Protocol: docs/protocol.md. Units: metres, newtons; Godot's global frame is the scene's world.

const Paths = preload("paths.gd")
const PROTOCOL = 1

# Every frame with a newer haptic state: the tool's position (Vector3, world [m]), orientation
# (Quat) and the device's buttons (int bit mask, bit i: button i).
signal move_on_haptic_tick(position, orientation, buttons)
signal session_started(scene_name)
# report: the `uh run --json` object; final_state: the state after the stop (zero force).
signal session_stopped(report, final_state)
signal contact_event(event)
signal service_error(message)
signal _reply(message)
signal _connection_result(ok)

export var host = "127.0.0.1"
export var port = 7770
# The uh program started when no service answers (environment UH_PROGRAM overrides it).
export var uh_program = "uh"
export var token = ""
# A scene file for the service to open (relative: to the project folder); empty: its default scene.
export var scene_path = ""
# The tool's device: a driver name ("sim-raster", "sim-line", "sim-circle", "sim-hand", ...) and
# its settings as JSON; empty: the scene's device.
export var device_driver = ""
export(String, MULTILINE) var device_config_json = ""
# Haptic and collision rates [Hz]; 0 (haptic) or < 0 (collision): the scene's.
export var haptic_hz = 0.0
export var collision_hz = -1.0
# The state stream's rate [Hz]; 0: the engine's frame rate (Engine.target_fps, else 60).
export var state_rate_hz = 0.0
export var autostart = true

var state = {}  # the newest "state" message
var force = Vector3()
var torque = Vector3()
var running = false
var tool_name = ""
var child_pid = 0  # the uh serve this node started, 0 if none
var last_error = ""

var _ws = null
var _open = false
var _waiting_id = ""
var _reply_taken = {}  # the reply to _waiting_id, for _wait_blocking
var _next_id = 0
var _new_state = false
var _starting = false
var _force_component = null
var _tool_node = null
var _volumes = []
var _sent_poses = {}
var _soft_nodes = {}  # object name -> the ColletteStaticMesh of a soft object
var _newest_deformed = {}  # object name -> the newest `deformed` entry not drawn yet


func _ready():
	if autostart:
		call_deferred("start_haptics")


func _process(_delta):
	if _ws != null:
		_ws.poll()
	if _new_state:
		_new_state = false
		emit_signal("move_on_haptic_tick", tool_position(), tool_orientation(), int(state.get("buttons", 0)))
	_draw_deformed()
	if running:
		_send_moved_poses()


func _exit_tree():
	stop_haptics()


# Called by ForceController / BridgingController / ColletteVolume when they enter the scene.
func register_force_component(component):
	_force_component = component


func register_tool(node):
	_tool_node = node


func register_volume(volume):
	if not volume in _volumes:
		_volumes.append(volume)


func tool_node():
	return _tool_node


func tool_position():
	return _vec3(state.get("tool", {}).get("position", [0, 0, 0]))


func tool_orientation():
	var q = state.get("tool", {}).get("orientation", [1, 0, 0, 0])
	return Quat(q[1], q[2], q[3], q[0])


# The ColletteStaticMesh nodes in the scene.
func static_meshes():
	return get_tree().get_nodes_in_group("collette_static_mesh")


# Connects, sends the scene and starts the session (a coroutine: yield(start_haptics(), "completed")
# returns true once the session runs). Errors: last_error and service_error.
func start_haptics():
	yield(get_tree(), "idle_frame")
	if running or _starting:
		return running
	_starting = true
	var ok = yield(_start(), "completed")
	_starting = false
	return ok


func _start():
	yield(get_tree(), "idle_frame")
	var connected = yield(_connect_service(), "completed")
	if not connected:
		return _fail("no uh serve answers at ws://%s:%d/ws and starting one failed (uh_program '%s')" % [host, port, _program()])
	var hello = {"type": "hello", "protocol": PROTOCOL}
	if token != "":
		hello["token"] = token
	if not _ok(yield(_request(hello), "completed")):
		return false
	var open = {"type": "open"}
	if scene_path != "":
		open["scene"] = Paths.absolute(scene_path)
	var opened = yield(_request(open), "completed")
	if not _ok(opened):
		return false
	tool_name = opened["tool"]
	var defaults = opened["objects"]
	var edits = []
	if device_driver != "":
		var device = {"driver": device_driver}
		if device_config_json.strip_edges() != "":
			var config = JSON.parse(device_config_json)
			if config.error != OK or typeof(config.result) != TYPE_DICTIONARY:
				return _fail("device_config_json: not a JSON object: %s" % config.error_string)
			device["config"] = config.result
		edits.append({"type": "set_device", "device": device})
	if haptic_hz > 0 or collision_hz >= 0:
		var rates = {"type": "set_rates"}
		if haptic_hz > 0:
			rates["haptic_hz"] = haptic_hz
		if collision_hz >= 0:
			rates["collision_hz"] = collision_hz
		edits.append(rates)
	if _force_component != null:
		edits.append({"type": "set_tool", "tool": _force_component.tool_patch()})
	for e in edits:
		if not _ok(yield(_request(e), "completed")):
			return false
	# the scene's objects are replaced by the Godot scene's ColletteStaticMesh nodes
	var added = []
	for node in static_meshes():
		var add = node.add_object_request()
		if add.has("error"):
			return _fail(add["error"])
		if not _ok(yield(_request(add["request"], add.get("frame")), "completed")):
			return false
		added.append(node.object_name())
		_sent_poses[node.object_name()] = node.global_transform
		if node.is_soft():
			var mesh = yield(_request({"type": "get_mesh", "object": node.object_name()}), "completed")
			if not _ok(mesh):
				return false
			node.show_soft_mesh(mesh)
			_soft_nodes[node.object_name()] = node
	if added.size() > 0:
		for name in defaults:
			if not name in added:
				if not _ok(yield(_request({"type": "remove_object", "name": name}), "completed")):
					return false
	var watched = []
	for volume in _volumes:
		for name in volume.watched_object_names(tool_name):
			if not name in watched:
				watched.append(name)
	if watched.size() > 0:
		if not _ok(yield(_request({"type": "set_watch", "objects": watched}), "completed")):
			return false
	var rate = state_rate_hz
	if rate <= 0:
		rate = Engine.target_fps if Engine.target_fps > 0 else 60
	if not _ok(yield(_request({"type": "subscribe", "rate_hz": clamp(rate, 1, 1000)}), "completed")):
		return false
	var started = yield(_request({"type": "start"}), "completed")
	if not _ok(started):
		return false
	running = true
	emit_signal("session_started", started["scene"])
	return true


# Stops the session (the service sends zero force at once and joins its threads), closes the
# connection and stops the service if this node started it. Blocks for at most a few seconds;
# safe to call at any time, also twice.
func stop_haptics():
	if _ws != null and _open and running:
		_next_id += 1
		var id = "gd%d" % _next_id
		_send(to_json({"type": "stop", "id": id}), null)
		var reply = _wait_blocking(id, 5000)
		running = false
		force = Vector3()
		torque = Vector3()
		if reply.get("type") == "stopped":
			emit_signal("session_stopped", reply.get("report"), reply.get("state", {}))
		else:
			_fail("stop: %s" % reply.get("message", "no answer from uh serve"))
	running = false
	if _ws != null:
		_ws.disconnect_from_host(1000, "the Godot scene stopped")
		_ws = null
	_open = false
	_stop_child()


func _stop_child():
	if child_pid == 0:
		return
	var pid = child_pid
	child_pid = 0
	if OS.get_name() == "Windows":
		OS.kill(pid)
		return
	# SIGTERM: uh serve stops any session (zero force) and exits; wait until it has
	OS.execute("kill", ["-TERM", str(pid)], true)
	for _i in range(250):
		if not process_alive(pid):
			return
		OS.delay_msec(20)
	OS.kill(pid)


# True while the process runs (Linux: an exited child that Godot has not reaped is a zombie).
static func process_alive(pid):
	var f = File.new()
	if f.open("/proc/%d/stat" % pid, File.READ) != OK:
		return false
	var fields = f.get_line().split(") ")
	f.close()
	return fields.size() > 1 and not fields[1].begins_with("Z")


func _program():
	var env = OS.get_environment("UH_PROGRAM")
	return env if env != "" else uh_program


func _connect_service():
	yield(get_tree(), "idle_frame")
	for attempt in range(200):
		_ws = WebSocketClient.new()
		# an inline mesh goes out as one frame: room for meshes up to 16 MiB
		_ws.set_buffers(1024, 4096, 16384, 4096)
		_ws.connect("connection_established", self, "_on_established")
		_ws.connect("connection_error", self, "_on_connection_error")
		_ws.connect("connection_closed", self, "_on_closed")
		_ws.connect("data_received", self, "_on_data")
		if _ws.connect_to_url("ws://%s:%d/ws" % [host, port]) == OK:
			var reached = yield(self, "_connection_result")
			if reached:
				_open = true
				return true
		_ws = null
		if attempt == 0:
			var args = ["serve", "--host", host, "--port", str(port)]
			if token != "":
				args += ["--token", token]
			child_pid = OS.execute(_program(), args, false)
			if child_pid <= 0:
				child_pid = 0
				return false
		elif child_pid != 0 and not process_alive(child_pid):
			child_pid = 0
			return false
		yield(get_tree().create_timer(0.05), "timeout")
	return false


# The connect coroutine resumes after the client's signal has returned (deferred): it may drop
# the client, which must not happen while the client emits.
func _on_established(_protocol):
	_ws.get_peer(1).set_write_mode(WebSocketPeer.WRITE_MODE_TEXT)
	call_deferred("emit_signal", "_connection_result", true)


func _on_connection_error():
	if _open:
		_on_closed(false)
	else:
		call_deferred("emit_signal", "_connection_result", false)


func _on_closed(_clean):
	_open = false
	running = false
	if _waiting_id != "":
		emit_signal("_reply", {"type": "error", "id": _waiting_id, "message": "the connection to uh serve closed"})


func _on_data():
	var peer = _ws.get_peer(1)
	while peer.get_available_packet_count() > 0:
		var parsed = JSON.parse(peer.get_packet().get_string_from_utf8())
		if parsed.error == OK and typeof(parsed.result) == TYPE_DICTIONARY:
			_dispatch(parsed.result)


func _dispatch(m):
	var type = m.get("type", "")
	if m.has("id") and str(m["id"]) == _waiting_id:
		_reply_taken = m
		emit_signal("_reply", m)
	elif type == "state":
		state = m
		force = _vec3(m["force"])
		torque = _vec3(m["torque"])
		_new_state = true
		for entry in m.get("deformed", []):
			if _soft_nodes.has(entry.get("object")):
				_newest_deformed[entry["object"]] = entry
		for volume in _volumes:
			volume.on_state(m)
	elif type == "contact":
		emit_signal("contact_event", m)
		for volume in _volumes:
			volume.on_contact(m)
	elif type == "stopped":
		# stopped by the service itself: a start with seconds, or the session ended by itself (a
		# device faulted or a thread ended; the force was zeroed), whose cause is `error`
		running = false
		emit_signal("session_stopped", m.get("report"), m.get("state", {}))
		if m.has("error"):
			_fail("uh serve: %s: %s" % [m.get("reason", "stopped"), m["error"]])
	elif type == "error":
		_fail("uh serve: %s" % m.get("message", ""))


func _send(text, frame):
	if _ws == null or not _open:
		return false
	var peer = _ws.get_peer(1)
	peer.set_write_mode(WebSocketPeer.WRITE_MODE_TEXT)
	if peer.put_packet(text.to_utf8()) != OK:
		return false
	if frame != null:
		peer.set_write_mode(WebSocketPeer.WRITE_MODE_BINARY)
		var sent = peer.put_packet(frame)
		peer.set_write_mode(WebSocketPeer.WRITE_MODE_TEXT)
		if sent != OK:
			return false
	return true


# A request and its reply (a coroutine); `frame`: the binary frame that follows it, or null.
func _request(message, frame = null):
	yield(get_tree(), "idle_frame")
	_next_id += 1
	var id = "gd%d" % _next_id
	message["id"] = id
	if not _send(to_json(message), frame):
		return {"type": "error", "id": id, "message": "%s: not connected to uh serve" % message["type"]}
	_waiting_id = id
	while true:
		var reply = yield(self, "_reply")
		if str(reply.get("id")) == id:
			_waiting_id = ""
			return reply


# The reply to request `id`, polling the socket on this thread (for stopping while leaving the tree;
# the client's data_received handler, _on_data, takes the packets and keeps the reply).
func _wait_blocking(id, timeout_ms):
	var until = OS.get_ticks_msec() + timeout_ms
	_waiting_id = id
	_reply_taken = {}
	while OS.get_ticks_msec() < until and _ws != null and _open and _reply_taken.empty():
		_ws.poll()
		OS.delay_msec(2)
	_waiting_id = ""
	return _reply_taken


# Each soft object's newest deformed surface, drawn once a frame. Drawing one takes longer than a
# state takes to come on a slow machine; drawn as each came, within the socket's poll (which reads
# for as long as data is waiting), the frame would never end while the service sends.
func _draw_deformed():
	var entries = _newest_deformed
	_newest_deformed = {}
	for name in entries:
		if _soft_nodes.has(name):
			_soft_nodes[name].on_deformed(entries[name])


func _send_moved_poses():
	for node in static_meshes():
		if not node.follow_node:
			continue
		var name = node.object_name()
		var t = node.global_transform
		if _sent_poses.has(name) and _sent_poses[name] == t:
			continue
		_sent_poses[name] = t
		_next_id += 1
		_send(to_json({"type": "set_pose", "id": "gd%d" % _next_id, "object": name, "pose": node.pose_json()}), null)


func _ok(reply):
	if reply.get("type") == "error":
		_fail("%s: %s" % [reply.get("request", "request"), reply.get("message", "")])
		return false
	return true


func _fail(message):
	last_error = message
	push_error("HapticManager: " + message)
	emit_signal("service_error", message)
	return false


static func _vec3(a):
	return Vector3(a[0], a[1], a[2])
