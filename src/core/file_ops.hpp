#pragma once
// The file system calls AtomicFileWriter makes, one implementation per system: file_ops_posix.cpp
// (open, write, fsync, rename, fsync of the directory) and file_ops_windows.cpp (the CRT's _wopen,
// _write, _commit, and MoveFileExW with write-through). Errors are errno values
// (std::generic_category), so that messages read the same everywhere.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <system_error>

namespace uh::detail {

/// Creates `path` for writing; fails if it exists. The descriptor is not inherited by children.
std::error_code create_new_file(const std::filesystem::path& path, int& fd);
/// Writes all `size` bytes (retrying short and interrupted writes).
std::error_code write_all(int fd, const char* data, std::size_t size);
/// Forces the file's content to the disk.
std::error_code sync_file(int fd);
std::error_code close_file(int fd);
/// Moves `from` over `to`, replacing it in one step.
std::error_code replace_file(const std::filesystem::path& from, const std::filesystem::path& to);
/// Makes a replace_file() into `dir` durable (POSIX: fsync of the directory; file systems that
/// cannot sync a directory are no failure). Windows: nothing to do, the move was written through.
std::error_code sync_directory(const std::filesystem::path& dir);
/// Removes a file; errors are ignored (used to clean up).
void remove_file(const std::filesystem::path& path);
/// What a path names, from the descriptor opened on it.
enum class FileKind { kRegular, kDirectory, kFifo, kDevice, kSocket, kOther };
/// Opens `path` for reading without ever blocking (POSIX: O_NONBLOCK, so that a FIFO without a
/// writer opens at once) and tells its kind and size from the open descriptor. Not inherited.
std::error_code open_for_reading(const std::filesystem::path& path, int& fd, FileKind& kind,
                                 std::uint64_t& size);
/// Reads up to `size` bytes into `data` (retrying interrupted reads); `got` is 0 at the end.
std::error_code read_some(int fd, char* data, std::size_t size, std::size_t& got);
/// This process's id, for names no other process uses at the same time.
long process_id();

}  // namespace uh::detail
