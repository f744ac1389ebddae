extends Node
# ForceComponent (the paper's ForceComponent): the tool's force law and its limits, sent to
# uh serve as the scene tool's `force` (docs/scenes.md); and optionally the tool's own mesh.

export(String, "6dof", "3dof") var mode = "6dof"
# The force law (docs/forcecomp.md): "gradient" (minus the gradient of the overlap volume) with its
# stiffness k [N/m^2] (force per unit of contact area), or "paper" (eq. 1) with eps_c [N/m^3];
# damping eps_d [N s/m].
export(String, "gradient", "paper") var law = "gradient"
export var stiffness = 2.0e4
export var force_scale = 1.0e7
export var damping = 2.0
# The tool's mass [kg] and the limits of its force [N] and torque [N m].
export var mass_kg = 0.05
export var max_force_n = 8.0
export var max_torque_nm = 0.3
# The tool's mesh (.obj or .ist; relative: to the project folder); empty: the scene's tool.
export var tool_mesh_path = ""
export var meters_per_unit = 1.0
export var spheres = 10000


# A merge patch of the scene's tool (uh serve's set_tool).
func tool_patch():
	var patch = {
		"force": {
			"mode": mode,
			"law": law,
			# each law has its own stiffness; the other one is removed (null in a merge patch)
			"stiffness": stiffness if law == "gradient" else null,
			"force_scale": force_scale if law == "paper" else null,
			"damping": damping,
			"mass_kg": mass_kg,
			"max_force_n": max_force_n,
			"max_torque_nm": max_torque_nm,
		}
	}
	if tool_mesh_path != "":
		var path = preload("paths.gd").absolute(tool_mesh_path)
		var key = "ist" if path.get_extension().to_lower() == "ist" else "mesh"
		patch[key] = path
		patch["mesh" if key == "ist" else "ist"] = null
		patch["meters_per_unit"] = meters_per_unit
		patch["spheres"] = spheres
	return patch
