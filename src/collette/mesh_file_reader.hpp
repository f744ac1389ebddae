#pragma once
// How load_mesh() reads a mesh file, before welding and validation: through assimp where the
// build has it (mesh_file_assimp.cpp), else with the in-tree OBJ/STL reader (mesh_file_builtin.cpp).

#include <filesystem>

#include "uh/collette/triangle_mesh.hpp"
#include "uh/core/result.hpp"

namespace uh::collette {

/// The file's triangles and vertices as they are; errors name the file. The file exists, is a
/// regular file and is not empty (load_mesh() checked).
Result<TriangleMesh> read_mesh_file(const std::filesystem::path& path);

/// True for the extensions read_obj_or_stl() reads (.obj, .stl, any case).
bool is_obj_or_stl(const std::filesystem::path& path);

}  // namespace uh::collette
