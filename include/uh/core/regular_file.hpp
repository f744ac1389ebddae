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

}  // namespace uh
