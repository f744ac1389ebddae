#pragma once
// The live view's page and bundled script (web/, built by esbuild), compiled into uh by
// cmake/UhEmbed.cmake; empty when the build has no live view (UH_BUILD_VIEW=OFF).

#include <span>
#include <string_view>
#include <vector>

#include "uh/service/server.hpp"

namespace uh::cli::view {

struct File {
  std::string_view path;  ///< e.g. "dist/view.js"
  std::string_view text;
};

std::span<const File> files();

/// The files as the server serves them ("/index.html", "/view.js").
std::vector<service::StaticFile> static_files();

}  // namespace uh::cli::view
