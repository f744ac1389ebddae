#include "museum_client.hpp"

#include <nlohmann/json.hpp>

#include "uh/collette/mesh_import.hpp"
#include "uh/museum_artifacts/artifact.hpp"
#include "view_assets.hpp"

namespace uh::cli {

MuseumClientFiles museum_client_files(const museum::Level& level) {
  MuseumClientFiles out;
  out.files = view::static_files("dist/museum");
  out.has_page = !out.files.empty();
  if (!out.has_page) return out;  // nobody to draw the looks (and no second of meshing at start)
  out.texts.reserve(level.artifact_kinds.size());  // the files point into the texts: no reallocation
  for (const std::string& name : level.artifact_kinds) {
    const auto kind = museum_artifacts::artifact_kind(name);
    if (!kind) continue;  // a kind the artifact set does not make has no picture; the client says so
    // 0.1 mm is finer than anything a picture shows: four decimals keep the file small
    nlohmann::json mesh = collette::mesh_json(
        museum_artifacts::artifact_mesh(*kind, level.difficulty, museum_artifacts::Piece::genuine), 1.0, 4);
    mesh["kind"] = name;
    out.texts.push_back(mesh.dump());
    out.files.push_back({.path = "/artifacts/" + name + ".json",
                         .content_type = "application/json",
                         .body = out.texts.back()});
  }
  return out;
}

}  // namespace uh::cli
