extends Spatial
# ColletteStaticMesh (the paper's ColletteStaticMeshActor): a static collision object. Its mesh is
# the MeshInstance child's mesh (every surface, through the child's transform and this node's
# scale), or `mesh_path`: an OBJ file (read here, drawn by a MeshInstance child made for it) or a
# prebuilt .ist file. The mesh is sent to uh serve inline (a binary frame), where it is packed with
# spheres as a mesh file would be; its pose is this node's global transform, and follows the node
# while the session runs (follow_node). The object's name in the service is the node's name.
# With `deformable_json` the object is soft (docs/deformables.md): the service's refined surface
# (get_mesh) is drawn by a MeshInstance child "SoftMesh" and follows the states' `deformed` vertices (the
# newest, once a frame).

const MeshData = preload("mesh_data.gd")
const Paths = preload("paths.gd")

# An .obj or .ist file (relative: to the project folder); empty: the MeshInstance child's mesh.
export var mesh_path = ""
# Length of one mesh unit [m] (Godot units are metres: 1).
export var meters_per_unit = 1.0
# Leaf spheres when packing the mesh.
export var spheres = 10000
# Send this node's pose whenever it moves while the session runs.
export var follow_node = true
# A soft object's `deformable` settings as a scene file's (docs/scenes.md); empty: rigid.
export(String, MULTILINE) var deformable_json = ""

var soft_updates = 0  # deformed surfaces drawn
var _obj = null  # the mesh read from mesh_path
var _soft_indices = null  # the soft surface's triangles, as get_mesh gave them, wound for Godot


func _enter_tree():
	add_to_group("collette_static_mesh")


func _ready():
	if mesh_path.get_extension().to_lower() == "obj" and _mesh_instance() == null:
		var data = _read_obj()
		if not data.has("error"):
			var instance = MeshInstance.new()
			instance.name = "Mesh"
			instance.mesh = MeshData.to_array_mesh(data)
			instance.scale = Vector3.ONE * meters_per_unit
			add_child(instance)


func object_name():
	return name


# {"position": [..], "rotation": [w, x, y, z]}: the node's global pose (scale is baked into the mesh).
func pose_json():
	var t = global_transform
	var q = t.basis.orthonormalized().get_rotation_quat()
	return {"position": [t.origin.x, t.origin.y, t.origin.z], "rotation": [q.w, q.x, q.y, q.z]}


# The add_object request for uh serve and the binary frame that follows it:
# {"request": {...}, "frame": PoolByteArray or null}, or {"error": message}.
func add_object_request():
	var object = {"name": object_name(), "spheres": spheres, "pose": pose_json()}
	if is_soft():
		var parsed = JSON.parse(deformable_json)
		if parsed.error != OK or typeof(parsed.result) != TYPE_DICTIONARY:
			return {"error": "%s: deformable_json is not a JSON object: %s" % [name, parsed.error_string]}
		object["deformable"] = parsed.result
	var extension = mesh_path.get_extension().to_lower()
	if extension == "ist":
		object["ist"] = Paths.absolute(mesh_path)
		return {"request": {"type": "add_object", "object": object}, "frame": null}
	var data
	var scale = global_transform.basis.get_scale()
	if extension == "obj":
		data = _read_obj()
		object["meters_per_unit"] = meters_per_unit
		if not data.has("error") and scale != Vector3.ONE:
			data = _scaled(data, scale)
	elif mesh_path != "":
		return {"error": "%s: mesh_path must be an .obj or .ist file" % name}
	else:
		var instance = _mesh_instance()
		if instance == null or instance.mesh == null:
			return {"error": "%s: no mesh_path and no MeshInstance child with a mesh" % name}
		data = MeshData.from_mesh(instance.mesh, Transform(Basis().scaled(scale)) * instance.transform)
		object["meters_per_unit"] = meters_per_unit
	if data.has("error"):
		return {"error": "%s: %s" % [name, data["error"]]}
	var request = {
		"type": "add_object",
		"object": object,
		"mesh_binary": {"vertices": data["vertices"].size(), "triangles": data["indices"].size() / 3},
	}
	return {"request": request, "frame": MeshData.encode_frame(data)}


func is_soft():
	return deformable_json.strip_edges() != ""


# Draws the soft surface of a get_mesh reply (`vertices`: flat [m] in the object's frame,
# counter-clockwise `triangles`) in place of this node's own mesh.
func show_soft_mesh(mesh):
	var idx = mesh["triangles"]
	_soft_indices = PoolIntArray()
	for t in range(idx.size() / 3):
		_soft_indices.append(idx[3 * t])
		_soft_indices.append(idx[3 * t + 2])
		_soft_indices.append(idx[3 * t + 1])
	for child in get_children():
		if child is MeshInstance:
			child.visible = false
	var instance = MeshInstance.new()
	instance.name = "SoftMesh"
	# the service's frame has no scale: undo this node's
	instance.transform = Transform(Basis().scaled(Vector3.ONE / global_transform.basis.get_scale()))
	add_child(instance)
	_draw_soft(_flat_vertices(mesh["vertices"], 1.0))


# A state's `deformed` entry for this object: its vertices, integers of unit_m, in get_mesh's order.
func on_deformed(entry):
	var vertices = _flat_vertices(entry["vertices"], float(entry["unit_m"]))
	if _soft_indices == null or vertices.size() * 3 != entry["vertices"].size():
		return
	_draw_soft(vertices)
	soft_updates += 1


func soft_mesh_instance():
	return get_node_or_null("SoftMesh")


func _draw_soft(vertices):
	var arrays = []
	arrays.resize(Mesh.ARRAY_MAX)
	arrays[Mesh.ARRAY_VERTEX] = vertices
	arrays[Mesh.ARRAY_INDEX] = _soft_indices
	var bare = ArrayMesh.new()
	bare.add_surface_from_arrays(Mesh.PRIMITIVE_TRIANGLES, arrays)
	# normals from the deformed surface, so a dent is shaded as one
	var tool = SurfaceTool.new()
	tool.create_from(bare, 0)
	tool.generate_normals()
	soft_mesh_instance().mesh = tool.commit()


static func _flat_vertices(flat, unit):
	var vertices = PoolVector3Array()
	for i in range(flat.size() / 3):
		vertices.append(Vector3(flat[3 * i], flat[3 * i + 1], flat[3 * i + 2]) * unit)
	return vertices


func _read_obj():
	if _obj == null:
		_obj = MeshData.read_obj(Paths.absolute(mesh_path))
	return _obj


func _scaled(data, scale):
	var vertices = PoolVector3Array()
	for v in data["vertices"]:
		vertices.append(v * scale)
	return {"vertices": vertices, "indices": data["indices"]}


func _mesh_instance():
	for child in get_children():
		if child is MeshInstance:
			return child
	return null
