#pragma once
// The binary frame of an inline mesh (`add_object` with `mesh_binary`, docs/protocol.md): decoded
// and checked byte by byte before anything else sees it. Never throws and never crashes on any
// input (fuzz/service_mesh_binary_fuzz.cpp); every error names the message and what is wrong.

#include <cstddef>
#include <span>
#include <string_view>

#include "protocol.hpp"
#include "uh/collette/triangle_mesh.hpp"
#include "uh/core/result.hpp"

namespace uh::service {

/// Decodes `frame` as `counts` announced it: the exact size, finite coordinates, indices below the
/// vertex count. `what` names the request in errors (e.g. "add_object 'bunny'"). The mesh is as
/// sent, in mesh units: welding, repair and the closed-mesh rules come after, as for a file.
Result<collette::TriangleMesh> decode_mesh_binary(std::span<const std::byte> frame, const MeshBinary& counts,
                                                  std::string_view what);

/// The frame `mesh` would be sent as (little-endian float32 vertices, uint32 indices): for
/// clients written in C++ and for tests.
std::string encode_mesh_binary(const collette::TriangleMesh& mesh);

}  // namespace uh::service
