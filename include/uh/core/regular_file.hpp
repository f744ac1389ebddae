#pragma once
/// \file
/// The one way the project opens a file that a user, a scene or a client names for reading (scene
/// files, meshes, .ist files): only a regular file is read, never a directory, FIFO, device or
/// socket, and never more than a limit given by the caller. The file is opened without blocking
/// (a FIFO without a writer would otherwise stall the caller, e.g. a server's network thread) and
/// its kind and size are checked on the open descriptor before a byte is read. Setup and
/// non-real-time threads only.

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "uh/core/result.hpp"

namespace uh {

/// Limits for the files the project reads (bytes); the docs (docs/security.md) list them.
inline constexpr std::uint64_t kMaxSceneFileBytes = std::uint64_t{16} << 20;
inline constexpr std::uint64_t kMaxMeshFileBytes = std::uint64_t{1} << 30;

/// The whole content of `path`, a regular file of at most `max_bytes`. Errors name the path and
/// what is wrong: "PATH: is a directory, not a file", "is a FIFO (named pipe), not a file",
/// "is a device, not a file", "N bytes is larger than the limit of M bytes", ...
Result<std::string> read_regular_file(const std::filesystem::path& path, std::uint64_t max_bytes);

/// The same checks without reading, for readers that open the path themselves (a mesh library):
/// the file's size in bytes, or the error read_regular_file() would give.
Result<std::uint64_t> check_regular_file(const std::filesystem::path& path, std::uint64_t max_bytes);

/// A folder files may be read from, and how messages name a file in it: `label/` and its path
/// relative to the folder (an empty label: the relative path alone, as for a service's root).
struct ReadableFolder {
  std::filesystem::path path;
  std::string label;
};

/// The folders a server reads the files its clients name from (`uh serve --root` and its cache),
/// or any folder. A path is inside a folder when it is after its symbolic links and `..` are
/// resolved, so a link inside that points outside is outside. The check is made before a file is
/// read; a user who can change the folders' links between the check and the read is trusted.
class ReadableFolders {
 public:
  /// Any path may be read (`uh serve --allow-any-path`, and every program but the servers).
  ReadableFolders() = default;
  /// Only paths in `folders` (made absolute and resolved here); messages name files outside
  /// relative to the first.
  explicit ReadableFolders(std::vector<ReadableFolder> folders);

  bool any_path() const { return folders_.empty(); }
  /// Ok when `path` (absolute) may be read; else "WHAT 'P' is outside the folders ..." with P named
  /// relative to the first folder.
  Status check(const std::filesystem::path& path, std::string_view what) const;
  /// `message` with each folder's absolute path replaced by its label, so that errors name files
  /// relative to the root and never show where the server keeps them.
  std::string shown(std::string message) const;

 private:
  std::vector<ReadableFolder> folders_;
};

}  // namespace uh
