extends Reference
# Paths the addon sends to uh serve: absolute file-system paths, whatever the editor shows.


# res:// and user:// paths globalised; a relative path is relative to the project folder; "." and
# ".." resolved (uh serve opens the file from its own working folder).
static func absolute(path: String) -> String:
	var p = path
	if p.begins_with("res://") or p.begins_with("user://"):
		p = ProjectSettings.globalize_path(p)
	elif not p.is_abs_path():
		p = ProjectSettings.globalize_path("res://").plus_file(p)
	var parts = []
	for part in p.replace("\\", "/").split("/"):
		if part == "..":
			if parts.size() > 1:
				parts.pop_back()
		elif part != "." and (part != "" or parts.empty()):
			parts.append(part)
	return PoolStringArray(parts).join("/")
