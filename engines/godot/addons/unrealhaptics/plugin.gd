tool
extends EditorPlugin
# Registers the addon's nodes in the editor's "Create New Node" dialog under the paper's names.
# The scripts work without the plugin enabled too (they are plain scripts on Node / Spatial).

const TYPES = [
	["HapticManager", "Node", "haptic_manager.gd"],
	["ColletteStaticMesh", "Spatial", "collette_static_mesh.gd"],
	["ColletteVolume", "Node", "collette_volume.gd"],
	["ForceComponent", "Node", "force_component.gd"],
	["BridgingController", "Node", "bridging_controller.gd"],
	["ForceController", "Node", "force_controller.gd"],
]


func _enter_tree():
	for t in TYPES:
		add_custom_type(t[0], t[1], load(get_script().resource_path.get_base_dir() + "/" + t[2]), null)


func _exit_tree():
	for t in TYPES:
		remove_custom_type(t[0])
