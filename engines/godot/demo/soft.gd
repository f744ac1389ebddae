extends Spatial
# The soft demo: the default scene's stylus, driven from 2 cm above a soft block to 8 mm into it
# (its force capped at 8 N) and back by a simulated line device (the block is scenes/soft_block.json's,
# E = 50 kPa, its base held);
# the block is the Godot scene's SoftBlock node (sent inline with its `deformable` settings), drawn
# from the service's refined surface, which follows the deformed vertices.


func _ready():
	var shaft = MeshInstance.new()
	var cylinder = CylinderMesh.new()
	cylinder.top_radius = 0.004
	cylinder.bottom_radius = 0.004
	cylinder.height = 0.05
	shaft.mesh = cylinder
	shaft.transform = Transform(Basis(Vector3.RIGHT, PI / 2), Vector3(0, 0, 0.025))
	$Stylus.add_child(shaft)
	$HapticManager.connect("service_error", self, "_on_error")


func _on_error(message):
	print("haptics: ", message)
