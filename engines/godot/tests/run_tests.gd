extends SceneTree
# Headless tests of the addon and the demo (scripts/godot-test.sh runs them with godot3-server
# against the uh program of the build): the demo's main scene is sent to uh serve (started as a
# child process), the tool's node follows the device, on_collision fires with force, and freeing
# the scene stops the session (zero force) and the service. Then the soft demo (soft.tscn): the
# block's drawn mesh goes down under the stylus. Ends with "N passed, N failed".

const HapticManagerScript = preload("res://addons/unrealhaptics/haptic_manager.gd")

var passed = 0
var failed = 0
var started = false
var collisions = []
var stopped = []
var moves = 0
var bad_buttons = 0  # the demo's raster script presses none: anything but int 0 is wrong


func _init():
	call_deferred("_run")


func check(ok, what):
	if ok:
		passed += 1
		print("ok: ", what)
	else:
		failed += 1
		print("FAILED: ", what)




func _run():
	var main = load("res://main.tscn").instance()
	var manager = main.get_node("HapticManager")
	manager.port = int(OS.get_environment("UH_TEST_PORT"))
	manager.connect("session_started", self, "_on_started")
	manager.connect("session_stopped", self, "_on_stopped")
	manager.connect("move_on_haptic_tick", self, "_on_move")
	main.get_node("ColletteVolume").connect("on_collision", self, "_on_collision")
	root.add_child(main)

	# the scene is sent: the session runs the Godot scene's bunny, sent inline, watched
	var until = OS.get_ticks_msec() + 120000
	while not started and manager.last_error == "" and OS.get_ticks_msec() < until:
		yield(create_timer(0.05), "timeout")
	check(started, "the session starts (%s)" % manager.last_error)
	print("uh serve pid ", manager.child_pid)
	check(manager.child_pid > 0, "the manager started uh serve as a child process")
	if not started:
		main.free()
		return finish()
	var scene = yield(manager._request({"type": "get_scene"}), "completed")
	var objects = scene.get("scene", {}).get("objects", [])
	check(objects.size() == 1 and objects[0]["name"] == "Bunny" and objects[0]["has_mesh"] and objects[0]["watched"],
		"the service's scene holds the Godot scene's bunny, inline and watched: %s" % to_json(objects))
	var rotation = objects[0]["pose"]["rotation"] if objects.size() == 1 else [0, 0, 0, 0]
	check(abs(rotation[0] - 0.7071068) < 1e-4 and abs(rotation[1] - 0.7071068) < 1e-4,
		"the bunny's pose is its node's: %s" % to_json(rotation))

	# the tool's node follows the device
	var stylus = main.get_node("Stylus")
	yield(create_timer(0.5), "timeout")
	var first = stylus.global_transform.origin
	var moves_before = moves
	yield(create_timer(0.5), "timeout")
	var second = stylus.global_transform.origin
	check(moves > moves_before, "move_on_haptic_tick comes every frame with a newer state (%d in 0.5 s)" % (moves - moves_before))
	check(bad_buttons == 0, "move_on_haptic_tick carries the device's buttons as an int (0 here, %d otherwise)" % bad_buttons)
	check(first.distance_to(second) > 1e-4, "the stylus moves with the device (%s -> %s)" % [first, second])
	check(second.distance_to(manager.tool_position()) < 1e-9, "the stylus is at the newest state's tool position")

	# on_collision fires with force
	until = OS.get_ticks_msec() + 30000
	while _collision_force() <= 0.0 and OS.get_ticks_msec() < until:
		yield(create_timer(0.1), "timeout")
	check(_has_event("begin"), "on_collision fires when the contact begins")
	check(_collision_force() > 0.0, "on_collision carries the force sent to the device (%.3f N)" % _collision_force())
	check(_collision_pairs() > 0, "on_collision carries the sphere pairs (%d)" % _collision_pairs())

	# stopping the scene stops the session (force to zero) and the service
	var pid = manager.child_pid
	main.queue_free()
	yield(create_timer(0.2), "timeout")
	check(stopped.size() == 1, "freeing the scene stops the session once (%d)" % stopped.size())
	if stopped.size() == 1:
		var report = stopped[0][0]
		var state = stopped[0][1]
		check(report != null and report["haptic"]["ticks"] > 0, "the stop returns the session's report")
		check(state.has("force") and state["force"] == [0.0, 0.0, 0.0],
			"the force sent to the device after the stop is zero: %s" % to_json(state.get("force")))
	check(not HapticManagerScript.process_alive(pid), "the uh serve the manager started has exited")
	yield(_run_soft(), "completed")
	finish()


# The soft demo: the block's SoftMesh is the service's refined surface, and its top under the stylus
# goes down as the deformed vertices come (driven from 2 cm above to 8 mm into E = 50 kPa).
func _run_soft():
	started = false
	var soft = load("res://soft.tscn").instance()
	var manager = soft.get_node("HapticManager")
	manager.port = int(OS.get_environment("UH_TEST_PORT"))
	manager.connect("session_started", self, "_on_started")
	root.add_child(soft)
	var until = OS.get_ticks_msec() + 120000
	while not started and manager.last_error == "" and OS.get_ticks_msec() < until:
		yield(create_timer(0.05), "timeout")
	print("uh serve pid ", manager.child_pid)
	check(started, "the soft demo's session starts (%s)" % manager.last_error)
	var block = soft.get_node("SoftBlock")
	var instance = block.soft_mesh_instance()
	check(instance != null and instance.mesh != null, "the soft block is drawn from the service's refined surface")
	if instance != null and instance.mesh != null:
		var vertices = instance.mesh.surface_get_arrays(0)[Mesh.ARRAY_VERTEX]
		# the block's top face is at z = 0 at rest: as get_mesh gave it (no deformed surface drawn
		# yet) exactly there; once the service's states came (it steps from the session's start)
		# pressed by the stylus, never pulled up
		var rest = 0.0
		var updated = block.soft_updates
		var first = _lowest_under_stylus(instance)
		var at_rest = abs(first - rest) < 1e-6 if updated == 0 else (first <= rest + 1e-6 and first > rest - 0.008)
		check(vertices.size() > 1000 and at_rest,
			"drawn: %d vertices, the top under the stylus at z = %.6f m (0 at rest; %d deformed surfaces drawn)"
			% [vertices.size(), first, updated])
		# watched for one whole press and release at least (the line's period is 4 s), sampled every
		# 0.1 s: the frames go on while the deformed surfaces come (they once stopped for minutes)
		var lowest = first
		var samples = 0
		var longest_ms = 0
		var last = OS.get_ticks_msec()
		until = last + 20000
		while (lowest > rest - 5e-4 or samples < 45) and OS.get_ticks_msec() < until:
			yield(create_timer(0.1), "timeout")
			samples += 1
			longest_ms = max(longest_ms, OS.get_ticks_msec() - last)
			last = OS.get_ticks_msec()
			lowest = min(lowest, _lowest_under_stylus(instance))
		check(lowest < rest - 1e-4, "the drawn block's top goes down under the stylus: %.2f mm (%d deformed surfaces drawn)"
			% [(lowest - rest) * 1000.0, block.soft_updates])
		check(samples >= 45 and longest_ms < 2000,
			"the frames go on while deformed surfaces come: %d samples of 0.1 s, the longest %d ms" % [samples, longest_ms])
	var pid = manager.child_pid
	soft.queue_free()
	yield(create_timer(0.2), "timeout")
	check(not HapticManagerScript.process_alive(pid), "the soft demo's uh serve has exited")


# The lowest z [m] of the drawn top face's vertices within 1 cm of the stylus (x = y = 0).
func _lowest_under_stylus(instance):
	var lowest = INF
	for v in instance.mesh.surface_get_arrays(0)[Mesh.ARRAY_VERTEX]:
		if abs(v.x) < 0.01 and abs(v.y) < 0.01 and v.z > -0.01:
			lowest = min(lowest, v.z)
	return lowest


func finish():
	print("%d passed, %d failed" % [passed, failed])
	quit(0 if failed == 0 else 1)


func _on_started(_scene):
	started = true


func _on_stopped(report, state):
	stopped.append([report, state])


func _on_move(_position, _orientation, buttons):
	moves += 1
	if typeof(buttons) != TYPE_INT or buttons != 0:
		bad_buttons += 1


func _on_collision(_a, _b, data):
	collisions.append(data)


func _has_event(kind):
	for c in collisions:
		if c["event"] == kind:
			return true
	return false


func _collision_force():
	var best = 0.0
	for c in collisions:
		best = max(best, c["force"].length())
	return best


func _collision_pairs():
	var best = 0
	for c in collisions:
		best = max(best, c["pairs"])
	return best
