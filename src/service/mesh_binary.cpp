#include "mesh_binary.hpp"

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>

#include <fmt/format.h>

namespace uh::service {
namespace {

// The frame is little-endian whatever the host is.
std::uint32_t load_le32(const std::byte* p) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<std::uint32_t>(p[i]);
  return v;
}

void store_le32(std::string& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xffu));
}

}  // namespace

Result<collette::TriangleMesh> decode_mesh_binary(std::span<const std::byte> frame, const MeshBinary& counts,
                                                  std::string_view what) {
  if (counts.vertices < 1 || counts.triangles < 1 ||
      counts.vertices + counts.triangles > static_cast<std::int64_t>(kMaxMeshBinaryBytes / 12))
    return Error{fmt::format("{}: mesh_binary counts {} vertices and {} triangles are out of range", what,
                             counts.vertices, counts.triangles)};
  if (frame.size() != counts.bytes())
    return Error{
        fmt::format("{}: the binary frame has {} bytes; mesh_binary announced {} vertices and {} "
                    "triangles, which take 12 * ({} + {}) = {} bytes",
                    what, frame.size(), counts.vertices, counts.triangles, counts.vertices, counts.triangles,
                    counts.bytes())};
  collette::TriangleMesh mesh;
  mesh.source_name = fmt::format("{} (mesh_binary)", what);
  const auto vertex_count = static_cast<std::size_t>(counts.vertices);
  const auto triangle_count = static_cast<std::size_t>(counts.triangles);
  mesh.vertices.reserve(vertex_count);
  const std::byte* p = frame.data();
  for (std::size_t i = 0; i < vertex_count; ++i) {
    double xyz[3];
    for (double& c : xyz) {
      c = static_cast<double>(std::bit_cast<float>(load_le32(p)));
      p += 4;
    }
    if (!std::isfinite(xyz[0]) || !std::isfinite(xyz[1]) || !std::isfinite(xyz[2]))
      return Error{fmt::format("{}: vertex {} is not finite ({}, {}, {})", what, i, xyz[0], xyz[1], xyz[2])};
    mesh.vertices.push_back(Vec3{xyz[0], xyz[1], xyz[2]});
  }
  mesh.triangles.reserve(triangle_count);
  for (std::size_t t = 0; t < triangle_count; ++t) {
    std::array<std::int32_t, 3> tri{};
    for (std::int32_t& index : tri) {
      const std::uint32_t v = load_le32(p);
      p += 4;
      if (v >= vertex_count)
        return Error{fmt::format("{}: triangle {} uses vertex {}, but there are only {} vertices (0..{})",
                                 what, t, v, vertex_count, vertex_count - 1)};
      index = static_cast<std::int32_t>(v);
    }
    mesh.triangles.push_back(tri);
  }
  return mesh;
}

std::string encode_mesh_binary(const collette::TriangleMesh& mesh) {
  std::string out;
  out.reserve((mesh.vertices.size() + mesh.triangles.size()) * 12);
  for (const Vec3& v : mesh.vertices)
    for (const double c : {v.x, v.y, v.z})
      store_le32(out, std::bit_cast<std::uint32_t>(static_cast<float>(c)));
  for (const auto& t : mesh.triangles)
    for (const std::int32_t i : t) store_le32(out, static_cast<std::uint32_t>(i));
  return out;
}

}  // namespace uh::service
