#pragma once
// The browser pages and their bundled scripts (web/, built by esbuild), compiled into uh by
// cmake/UhEmbed.cmake: the live view of `uh serve` (dist/) and Vive's client of `uh museum serve`
// (dist/museum/); empty when the build has no pages (UH_BUILD_VIEW=OFF).

#include <span>
#include <string_view>
#include <vector>

#include "uh/net/web_socket_host.hpp"

namespace uh::cli::view {

struct File {
  std::string_view path;  ///< e.g. "dist/view.js"
  std::string_view text;
};

std::span<const File> files();

/// The files of one page's folder as the server serves them: "dist" gives the live view
/// ("/index.html", "/view.js"), "dist/museum" Vive's client ("/index.html", "/museum.js").
std::vector<net::StaticFile> static_files(std::string_view folder = "dist");

}  // namespace uh::cli::view
