extends Spatial
# The demo: the Stanford bunny (assets/meshes, sent to uh serve inline) explored by the default
# scene's simulated device (a raster sweep into deep contact). The stylus follows the device; each
# contact's begin and end is printed with the force sent to the device.


func _ready():
	$ColletteVolume.connect("on_collision", self, "_on_collision")
	$HapticManager.connect("service_error", self, "_on_error")


func _on_collision(a, b, data):
	if data["event"] != "contact":
		print("%s %s %s: %d sphere pairs, force %.2f N" % [a.name, data["event"], b.name, data["pairs"], data["force"].length()])


func _on_error(message):
	print("haptics: ", message)
