#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>
#include <assimp/Importer.hpp>

#include "mesh_file_reader.hpp"

namespace uh::collette {

Result<TriangleMesh> read_mesh_file(const std::filesystem::path& path) {
  const std::string name = path.filename().string();
  Assimp::Importer importer;
  // no JoinIdenticalVertices: it also compares normals, so STL stays unwelded; we weld ourselves
  const aiScene* scene =
      importer.ReadFile(path.string(), aiProcess_Triangulate | aiProcess_PreTransformVertices);
  if (scene == nullptr) {
    return Error{fmt::format("{}: cannot read mesh: {}", name, importer.GetErrorString())};
  }
  TriangleMesh mesh;
  mesh.source_name = name;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* am = scene->mMeshes[m];
    const auto base = static_cast<std::int32_t>(mesh.vertices.size());
    for (unsigned i = 0; i < am->mNumVertices; ++i) {
      const aiVector3D& v = am->mVertices[i];
      mesh.vertices.push_back({static_cast<double>(v.x), static_cast<double>(v.y), static_cast<double>(v.z)});
    }
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines carry no surface
      mesh.triangles.push_back({base + static_cast<std::int32_t>(face.mIndices[0]),
                                base + static_cast<std::int32_t>(face.mIndices[1]),
                                base + static_cast<std::int32_t>(face.mIndices[2])});
    }
  }
  return mesh;
}

}  // namespace uh::collette
