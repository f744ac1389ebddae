extends Reference
# Meshes as uh serve takes them inline (docs/protocol.md, "Inline meshes"): vertices and triangle
# indices, read from an OBJ file or from a Godot Mesh, and packed into the binary frame that
# follows an add_object announcing "mesh_binary" (little-endian float32 x, y, z per vertex, then
# little-endian uint32 indices, three per triangle).


# Reads the vertices ("v") and faces ("f", polygons fanned into triangles) of an OBJ file.
# Returns {"vertices": PoolVector3Array, "indices": PoolIntArray} or {"error": message}.
static func read_obj(path: String) -> Dictionary:
	var f = File.new()
	if f.open(path, File.READ) != OK:
		return {"error": "%s: cannot open the mesh file" % path}
	var vertices = PoolVector3Array()
	var indices = PoolIntArray()
	var line_number = 0
	while not f.eof_reached():
		var line = f.get_line().strip_edges()
		line_number += 1
		if line.begins_with("v "):
			var p = line.split(" ", false)
			if p.size() < 4:
				f.close()
				return {"error": "%s:%d: a vertex needs three coordinates" % [path, line_number]}
			vertices.append(Vector3(float(p[1]), float(p[2]), float(p[3])))
		elif line.begins_with("f "):
			var p = line.split(" ", false)
			var face = []
			for i in range(1, p.size()):
				var k = int(p[i].split("/")[0])
				face.append(k - 1 if k > 0 else vertices.size() + k)
			for i in range(1, face.size() - 1):
				indices.append(face[0])
				indices.append(face[i])
				indices.append(face[i + 1])
	f.close()
	if vertices.size() == 0 or indices.size() == 0:
		return {"error": "%s: no vertices or faces" % path}
	return {"vertices": vertices, "indices": indices}


# The triangles of every surface of a Godot Mesh, each vertex through `transform`. Godot's front
# faces are clockwise; the service flips a mesh wound that way, as it does for mesh files.
static func from_mesh(mesh: Mesh, transform: Transform) -> Dictionary:
	var vertices = PoolVector3Array()
	var indices = PoolIntArray()
	for s in range(mesh.get_surface_count()):
		var arrays = mesh.surface_get_arrays(s)
		var base = vertices.size()
		var surface_vertices = arrays[Mesh.ARRAY_VERTEX]
		for v in surface_vertices:
			vertices.append(transform.xform(v))
		var surface_indices = arrays[Mesh.ARRAY_INDEX]
		if surface_indices == null or surface_indices.size() == 0:
			for i in range(surface_vertices.size()):
				indices.append(base + i)
		else:
			for i in surface_indices:
				indices.append(base + i)
	if vertices.size() == 0:
		return {"error": "the mesh has no vertices"}
	return {"vertices": vertices, "indices": indices}


# An ArrayMesh to draw what read_obj() returned (OBJ faces are counter-clockwise; Godot draws
# clockwise front faces, so each triangle is reversed).
static func to_array_mesh(data: Dictionary) -> ArrayMesh:
	var drawn = PoolIntArray()
	var idx = data["indices"]
	for t in range(idx.size() / 3):
		drawn.append(idx[3 * t])
		drawn.append(idx[3 * t + 2])
		drawn.append(idx[3 * t + 1])
	var arrays = []
	arrays.resize(Mesh.ARRAY_MAX)
	arrays[Mesh.ARRAY_VERTEX] = data["vertices"]
	arrays[Mesh.ARRAY_INDEX] = drawn
	var mesh = ArrayMesh.new()
	mesh.add_surface_from_arrays(Mesh.PRIMITIVE_TRIANGLES, arrays)
	return mesh


# The binary frame of an inline mesh.
static func encode_frame(data: Dictionary) -> PoolByteArray:
	var b = StreamPeerBuffer.new()
	b.big_endian = false
	for v in data["vertices"]:
		b.put_float(v.x)
		b.put_float(v.y)
		b.put_float(v.z)
	for i in data["indices"]:
		b.put_u32(i)
	return b.data_array
