// libFuzzer target for the binary frame of an inline mesh (uh serve's add_object with
// mesh_binary, docs/protocol.md). The input is a 4-byte header, the announced vertex and triangle
// counts as two little-endian uint16, followed by the frame. Any input must give a mesh or an
// error naming the request, never a crash; a mesh must hold exactly the announced counts, finite
// coordinates and indices below the vertex count, and encode back to the same frame.
// Seeds: fuzz/mesh_binary_seeds/ (a tetrahedron; scripts/test.sh passes it read-only).

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <string>

#include "mesh_binary.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace uh::service;
  if (size < 4) return 0;
  const MeshBinary counts{.vertices = data[0] | (data[1] << 8), .triangles = data[2] | (data[3] << 8)};
  const auto frame = std::as_bytes(std::span(data + 4, size - 4));
  auto mesh = decode_mesh_binary(frame, counts, "add_object 'fuzz'");
  if (!mesh) {
    if (mesh.error().message.rfind("add_object 'fuzz': ", 0) != 0) std::abort();
    return 0;
  }
  if (std::ssize(mesh->vertices) != counts.vertices || std::ssize(mesh->triangles) != counts.triangles)
    std::abort();
  for (const auto& v : mesh->vertices)
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) std::abort();
  for (const auto& t : mesh->triangles)
    for (const std::int32_t i : t)
      if (i < 0 || i >= counts.vertices) std::abort();
  const std::string again = encode_mesh_binary(*mesh);
  if (again.size() != frame.size()) std::abort();
  return 0;
}
