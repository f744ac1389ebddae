#pragma once
// What `uh museum serve` serves over HTTP for Vive's browser client (web/src/museum.js,
// docs/museum.md): the page and its bundled script at `/`, and every artifact kind's look as
// `/artifacts/KIND.json` {"kind", "vertices": [x, y, z, ...], "triangles": [i, j, k, ...]} (metres,
// the piece standing on z = 0) for the pictures Falcon shows and the pieces drawn in the cases.

#include <string>
#include <vector>

#include "uh/museum/level.hpp"
#include "uh/net/web_socket_host.hpp"

namespace uh::cli {

/// The files and the texts they point into (keep it alive while the server runs).
struct MuseumClientFiles {
  std::vector<std::string> texts;
  std::vector<net::StaticFile> files;
  bool has_page = false;  ///< whether the build bundled the page (UH_BUILD_VIEW)
};

/// The page and the looks of `level`'s artifact kinds (a piece's genuine mesh stands for both: a
/// forgery looks the same); nothing without UH_BUILD_VIEW.
MuseumClientFiles museum_client_files(const museum::Level& level);

}  // namespace uh::cli
