#pragma once
// Files compiled into the library (cmake/UhEmbed.cmake): the default scene and its meshes, so that
// `uh run` works without the source tree.

#include <span>
#include <string_view>

namespace uh::scene::embedded {

struct File {
  std::string_view path;  ///< relative path, as in the source tree
  std::string_view text;
};

std::span<const File> files();
std::string_view default_scene_json();

}  // namespace uh::scene::embedded
