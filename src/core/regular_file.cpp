#include "uh/core/regular_file.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "file_ops.hpp"

namespace uh {
namespace {

const char* not_a_file(detail::FileKind kind) {
  switch (kind) {
    case detail::FileKind::kRegular:
      return nullptr;
    case detail::FileKind::kDirectory:
      return "is a directory, not a file";
    case detail::FileKind::kFifo:
      return "is a FIFO (named pipe), not a file";
    case detail::FileKind::kDevice:
      return "is a device, not a file";
    case detail::FileKind::kSocket:
      return "is a socket, not a file";
    case detail::FileKind::kOther:
      break;
  }
  return "is not a regular file";
}

// An open descriptor, closed when it goes out of scope.
class OpenFile {
 public:
  OpenFile() = default;
  ~OpenFile() {
    if (fd >= 0) detail::close_file(fd);
  }
  OpenFile(const OpenFile&) = delete;
  OpenFile& operator=(const OpenFile&) = delete;
  int fd = -1;
};

// Opens `path` and checks its kind and size: the size, or the error naming the path.
Result<std::uint64_t> open_checked(const std::filesystem::path& path, std::uint64_t max_bytes,
                                   OpenFile& file) {
  detail::FileKind kind = detail::FileKind::kOther;
  std::uint64_t size = 0;
  if (const std::error_code ec = detail::open_for_reading(path, file.fd, kind, size))
    return Error{fmt::format("{}: cannot open the file: {}", path.string(), ec.message()), ErrorKind::kFile};
  if (const char* what = not_a_file(kind))
    return Error{fmt::format("{}: {}", path.string(), what), ErrorKind::kFile};
  if (size > max_bytes)
    return Error{fmt::format("{}: {} bytes is larger than the limit of {} bytes for this file", path.string(),
                             size, max_bytes),
                 ErrorKind::kFile};
  return size;
}

}  // namespace

Result<std::string> read_regular_file(const std::filesystem::path& path, std::uint64_t max_bytes) {
  OpenFile file;
  auto size = open_checked(path, max_bytes, file);
  if (!size) return size.error();
  // the size was checked on the open file; one that grows meanwhile is still read only up to the
  // limit (one byte more tells that it grew past it)
  std::string bytes(static_cast<std::size_t>(*size), '\0');
  std::size_t total = 0;
  for (;;) {
    if (total == bytes.size()) {
      if (total > max_bytes) break;
      bytes.resize(std::min<std::uint64_t>(max_bytes + 1, total + (std::uint64_t{1} << 16)));
    }
    std::size_t got = 0;
    if (const std::error_code ec =
            detail::read_some(file.fd, bytes.data() + total, bytes.size() - total, got))
      return Error{fmt::format("{}: read error: {}", path.string(), ec.message()), ErrorKind::kFile};
    if (got == 0) break;
    total += got;
  }
  if (total > max_bytes)
    return Error{fmt::format("{}: the file grew past the limit of {} bytes while it was read", path.string(),
                             max_bytes),
                 ErrorKind::kFile};
  bytes.resize(total);
  return bytes;
}

Result<std::uint64_t> check_regular_file(const std::filesystem::path& path, std::uint64_t max_bytes) {
  OpenFile file;
  return open_checked(path, max_bytes, file);
}

}  // namespace uh
