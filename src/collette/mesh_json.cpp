// The mesh's JSON form, written and read in one place (mesh_import.hpp).
#include <array>
#include <cmath>
#include <cstddef>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "uh/collette/mesh_import.hpp"
#include "uh/core/json_fields.hpp"

namespace uh::collette {

nlohmann::json mesh_json(const TriangleMesh& mesh, double scale, int decimals) {
  // dividing the rounded integer by a power of ten gives the double nearest the decimal, which
  // JSON then prints with no more digits than `decimals`
  const double places = decimals >= 0 ? std::pow(10.0, decimals) : 0.0;
  const auto coordinate = [&](double x) { return places > 0.0 ? std::round(x * scale * places) / places : x * scale; };
  nlohmann::json vertices = nlohmann::json::array();
  nlohmann::json triangles = nlohmann::json::array();
  vertices.get_ref<nlohmann::json::array_t&>().reserve(3 * mesh.vertices.size());
  triangles.get_ref<nlohmann::json::array_t&>().reserve(3 * mesh.triangles.size());
  for (const Vec3& v : mesh.vertices) {
    vertices.push_back(coordinate(v.x));
    vertices.push_back(coordinate(v.y));
    vertices.push_back(coordinate(v.z));
  }
  for (const auto& t : mesh.triangles)
    for (const std::int32_t i : t) triangles.push_back(i);
  return nlohmann::json{{"vertices", std::move(vertices)}, {"triangles", std::move(triangles)}};
}

Result<TriangleMesh> parse_mesh_json(std::string_view text, const std::string& name) {
  auto document = parse_json_document(text);
  if (!document) return Error{fmt::format("{}: {}", name, document.error().message)};
  JsonFields fields;
  const nlohmann::json* vertices = fields.array(*document, "vertices");
  const nlohmann::json* triangles = fields.array(*document, "triangles");
  if (fields.ok() && vertices->size() % 3 != 0)
    fields.fail("vertices", fmt::format("has {} numbers, not x, y, z per vertex", vertices->size()));
  if (fields.ok() && triangles->size() % 3 != 0)
    fields.fail("triangles", fmt::format("has {} indices, not three per triangle", triangles->size()));
  TriangleMesh mesh;
  mesh.source_name = name;
  for (std::size_t i = 0; fields.ok() && i + 2 < vertices->size(); i += 3) {
    const auto at = [&](std::size_t k) { return fields.number_of((*vertices)[k], fmt::format("vertices[{}]", k)); };
    mesh.vertices.push_back({at(i), at(i + 1), at(i + 2)});
  }
  for (std::size_t i = 0; fields.ok() && i + 2 < triangles->size(); i += 3) {
    std::array<std::int32_t, 3> t{};
    for (std::size_t c = 0; c < 3; ++c) {
      const int corner = fields.integer_of((*triangles)[i + c], fmt::format("triangles[{}]", i + c));
      if (fields.ok() && (corner < 0 || static_cast<std::size_t>(corner) >= mesh.vertices.size()))
        fields.fail(fmt::format("triangles[{}]", i + c),
                    fmt::format("is {}, not the index of one of the {} vertices", corner, mesh.vertices.size()));
      t[c] = corner;
    }
    mesh.triangles.push_back(t);
  }
  if (!fields.ok()) return Error{fmt::format("{}: {}", name, fields.error())};
  return mesh;
}

}  // namespace uh::collette
