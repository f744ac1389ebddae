#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>

#include "file_ops.hpp"

namespace uh::detail {
namespace {

std::error_code last_error() { return {errno, std::generic_category()}; }

}  // namespace

std::error_code create_new_file(const std::filesystem::path& path, int& fd) {
  fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  return fd < 0 ? last_error() : std::error_code{};
}

std::error_code write_all(int fd, const char* data, std::size_t size) {
  while (size > 0) {
    const ssize_t w = ::write(fd, data, size);
    if (w < 0) {
      if (errno == EINTR) continue;
      return last_error();
    }
    data += w;
    size -= static_cast<std::size_t>(w);
  }
  return {};
}

std::error_code sync_file(int fd) { return ::fsync(fd) != 0 ? last_error() : std::error_code{}; }

std::error_code close_file(int fd) { return ::close(fd) != 0 ? last_error() : std::error_code{}; }

std::error_code replace_file(const std::filesystem::path& from, const std::filesystem::path& to) {
  return ::rename(from.c_str(), to.c_str()) != 0 ? last_error() : std::error_code{};
}

// file systems that cannot sync a directory say EINVAL; the rename has happened then
std::error_code sync_directory(const std::filesystem::path& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return {};
  const int synced = ::fsync(fd);
  const int error = errno;
  ::close(fd);
  return synced != 0 && error != EINVAL ? std::error_code(error, std::generic_category()) : std::error_code{};
}

void remove_file(const std::filesystem::path& path) { ::unlink(path.c_str()); }

std::error_code open_for_reading(const std::filesystem::path& path, int& fd, FileKind& kind,
                                 std::uint64_t& size) {
  fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
  if (fd < 0) return last_error();
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    const std::error_code error = last_error();
    ::close(fd);
    fd = -1;
    return error;
  }
  kind = S_ISREG(st.st_mode)                          ? FileKind::kRegular
         : S_ISDIR(st.st_mode)                        ? FileKind::kDirectory
         : S_ISFIFO(st.st_mode)                       ? FileKind::kFifo
         : S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode) ? FileKind::kDevice
         : S_ISSOCK(st.st_mode)                       ? FileKind::kSocket
                                                      : FileKind::kOther;
  size = st.st_size > 0 ? static_cast<std::uint64_t>(st.st_size) : 0;
  return {};
}

std::error_code read_some(int fd, char* data, std::size_t size, std::size_t& got) {
  for (;;) {
    const ssize_t r = ::read(fd, data, size);
    if (r >= 0) {
      got = static_cast<std::size_t>(r);
      return {};
    }
    if (errno != EINTR) return last_error();
  }
}

long process_id() { return static_cast<long>(::getpid()); }

}  // namespace uh::detail
