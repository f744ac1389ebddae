#include <windows.h>
// after windows.h
#include <fcntl.h>
#include <io.h>
#include <process.h>
#include <sys/stat.h>

#include <cerrno>
#include <climits>

#include "file_ops.hpp"

namespace uh::detail {
namespace {

std::error_code last_error() { return {errno, std::generic_category()}; }

// MoveFileExW reports a Windows error code: the errno values that say the same
int errno_of(DWORD error) {
  switch (error) {
    case ERROR_FILE_NOT_FOUND:
    case ERROR_PATH_NOT_FOUND:
      return ENOENT;
    case ERROR_ACCESS_DENIED:
    case ERROR_SHARING_VIOLATION:
    case ERROR_LOCK_VIOLATION:
      return EACCES;
    case ERROR_DISK_FULL:
    case ERROR_HANDLE_DISK_FULL:
      return ENOSPC;
    case ERROR_NOT_SAME_DEVICE:
      return EXDEV;
    case ERROR_WRITE_PROTECT:
      return EROFS;
    default:
      return EIO;
  }
}

}  // namespace

std::error_code create_new_file(const std::filesystem::path& path, int& fd) {
  fd =
      ::_wopen(path.c_str(), _O_WRONLY | _O_CREAT | _O_EXCL | _O_BINARY | _O_NOINHERIT, _S_IREAD | _S_IWRITE);
  return fd < 0 ? last_error() : std::error_code{};
}

std::error_code write_all(int fd, const char* data, std::size_t size) {
  while (size > 0) {
    const unsigned chunk = size > INT_MAX ? INT_MAX : static_cast<unsigned>(size);
    const int w = ::_write(fd, data, chunk);
    if (w < 0) return last_error();
    data += w;
    size -= static_cast<std::size_t>(w);
  }
  return {};
}

std::error_code sync_file(int fd) { return ::_commit(fd) != 0 ? last_error() : std::error_code{}; }

std::error_code close_file(int fd) { return ::_close(fd) != 0 ? last_error() : std::error_code{}; }

// the write-through flag returns only once the move is on the disk: no directory sync to follow
std::error_code replace_file(const std::filesystem::path& from, const std::filesystem::path& to) {
  if (MoveFileExW(from.c_str(), to.c_str(), MOVEFILE_REPLACE_EXISTING | MOVEFILE_WRITE_THROUGH)) return {};
  return {errno_of(GetLastError()), std::generic_category()};
}

std::error_code sync_directory(const std::filesystem::path&) { return {}; }

void remove_file(const std::filesystem::path& path) { ::_wunlink(path.c_str()); }

// the CRT cannot open a folder: it is named as one rather than as a refused open
std::error_code open_for_reading(const std::filesystem::path& path, int& fd, FileKind& kind,
                                 std::uint64_t& size) {
  std::error_code status_error;
  if (std::filesystem::is_directory(path, status_error)) {
    fd = -1;
    kind = FileKind::kDirectory;
    size = 0;
    return {};
  }
  fd = ::_wopen(path.c_str(), _O_RDONLY | _O_BINARY | _O_NOINHERIT);
  if (fd < 0) return last_error();
  struct _stat64 st {};
  if (::_fstat64(fd, &st) != 0) {
    const std::error_code error = last_error();
    ::_close(fd);
    fd = -1;
    return error;
  }
  const auto type = st.st_mode & _S_IFMT;
  kind = type == _S_IFREG   ? FileKind::kRegular
         : type == _S_IFCHR ? FileKind::kDevice
         : type == _S_IFIFO ? FileKind::kFifo
                            : FileKind::kOther;
  size = st.st_size > 0 ? static_cast<std::uint64_t>(st.st_size) : 0;
  return {};
}

std::error_code read_some(int fd, char* data, std::size_t size, std::size_t& got) {
  const unsigned chunk = size > INT_MAX ? INT_MAX : static_cast<unsigned>(size);
  const int r = ::_read(fd, data, chunk);
  if (r < 0) return last_error();
  got = static_cast<std::size_t>(r);
  return {};
}

long process_id() { return static_cast<long>(::_getpid()); }

}  // namespace uh::detail
