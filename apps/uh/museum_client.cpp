#include "museum_client.hpp"

#include <iterator>

#include <fmt/format.h>

#include "uh/museum_artifacts/artifact.hpp"
#include "view_assets.hpp"

namespace uh::cli {

namespace {

// A mesh as compact JSON: 0.1 mm is finer than anything a picture shows.
std::string mesh_json(const std::string& kind, const collette::TriangleMesh& mesh) {
  std::string out = fmt::format(R"({{"kind":"{}","vertices":[)", kind);
  const char* sep = "";
  for (const auto& v : mesh.vertices) {
    fmt::format_to(std::back_inserter(out), "{}{:.4f},{:.4f},{:.4f}", sep, v.x, v.y, v.z);
    sep = ",";
  }
  out += R"(],"triangles":[)";
  sep = "";
  for (const auto& t : mesh.triangles) {
    fmt::format_to(std::back_inserter(out), "{}{},{},{}", sep, t[0], t[1], t[2]);
    sep = ",";
  }
  out += "]}";
  return out;
}

}  // namespace

MuseumClientFiles museum_client_files(const museum::Level& level) {
  MuseumClientFiles out;
  out.files = view::static_files("dist/museum");
  out.has_page = !out.files.empty();
  if (!out.has_page) return out;  // nobody to draw the looks (and no second of meshing at start)
  out.texts.reserve(level.artifact_kinds.size());  // the files point into the texts: no reallocation
  for (const std::string& name : level.artifact_kinds) {
    const auto kind = museum_artifacts::artifact_kind(name);
    if (!kind) continue;  // a kind the artifact set does not make has no picture; the client says so
    out.texts.push_back(mesh_json(
        name, museum_artifacts::artifact_mesh(*kind, level.difficulty, museum_artifacts::Piece::genuine)));
    out.files.push_back({.path = "/artifacts/" + name + ".json",
                         .content_type = "application/json",
                         .body = out.texts.back()});
  }
  return out;
}

}  // namespace uh::cli
