#include "view_assets.hpp"

#include <filesystem>
#include <string>

namespace uh::cli::view {

std::vector<net::StaticFile> static_files(std::string_view folder) {
  std::vector<net::StaticFile> out;
  for (const File& f : files()) {
    const std::filesystem::path path(f.path);
    if (path.parent_path() != std::filesystem::path(folder)) continue;
    const std::string ext = path.extension().string();
    const char* type = ext == ".html" ? "text/html; charset=utf-8"
                       : ext == ".js" ? "text/javascript; charset=utf-8"
                                      : "application/octet-stream";
    std::string served = "/";  // (not "/" + name: g++ 12 reports a false -Wrestrict for that)
    served += path.filename().string();
    out.push_back({.path = std::move(served), .content_type = type, .body = f.text});
  }
  return out;
}

}  // namespace uh::cli::view
