#include <fcntl.h>
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

long process_id() { return static_cast<long>(::getpid()); }

}  // namespace uh::detail
