#include <fmt/format.h>

#include "mesh_file_reader.hpp"
#include "uh/collette/mesh_import.hpp"

namespace uh::collette {

// builds without assimp (the Windows build): OBJ and STL only, and a message that says why
Result<TriangleMesh> read_mesh_file(const std::filesystem::path& path) {
  if (!is_obj_or_stl(path)) {
    return Error{
        fmt::format("{}: cannot read mesh: this build reads OBJ (.obj) and STL (.stl) files only (it has "
                    "no assimp, like the Windows build); convert the mesh to OBJ or STL",
                    path.filename().string())};
  }
  return read_obj_or_stl(path);
}

}  // namespace uh::collette
