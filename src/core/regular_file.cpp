#include "uh/core/regular_file.hpp"

#include <algorithm>
#include <cctype>
#include <system_error>

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

namespace {

// `path` made absolute with its links and `..` resolved as far as it exists (the rest lexically)
std::filesystem::path resolved(const std::filesystem::path& path, int links_followed = 0) {
  std::error_code ec;
  std::filesystem::path absolute = std::filesystem::absolute(path, ec);
  if (ec) absolute = path;
  // a link whose target is missing is followed here: weakly_canonical would keep the link's name
  if (links_followed < 40 && std::filesystem::is_symlink(absolute, ec)) {
    const std::filesystem::path target = std::filesystem::read_symlink(absolute, ec);
    if (!ec)
      return resolved(target.is_absolute() ? target : absolute.parent_path() / target, links_followed + 1);
  }
  std::filesystem::path canonical = std::filesystem::weakly_canonical(absolute, ec);
  return ec ? absolute.lexically_normal() : canonical;
}

bool is_within(const std::filesystem::path& path, const std::filesystem::path& folder) {
  // by whole components: /srv/data-old is not within /srv/data
  const auto [in_folder, in_path] = std::mismatch(folder.begin(), folder.end(), path.begin(), path.end());
  return in_folder == folder.end() || (std::next(in_folder) == folder.end() && in_folder->empty());
}

}  // namespace

ReadableFolders::ReadableFolders(std::vector<ReadableFolder> folders) : folders_(std::move(folders)) {
  for (ReadableFolder& f : folders_) f.path = resolved(f.path);
}

Status ReadableFolders::check(const std::filesystem::path& path, std::string_view what) const {
  if (any_path()) return Ok{};
  const std::filesystem::path file = resolved(path);
  for (const ReadableFolder& f : folders_)
    if (is_within(file, f.path)) return Ok{};
  return Error{fmt::format("{} '{}' is outside the folders this server reads from (its root and its cache)",
                           what, file.lexically_relative(folders_.front().path).generic_string())};
}

std::string ReadableFolders::shown(std::string message) const {
  // the longest folder first: a cache inside the root is named as the cache
  std::vector<const ReadableFolder*> longest_first;
  for (const ReadableFolder& f : folders_) longest_first.push_back(&f);
  std::sort(longest_first.begin(), longest_first.end(), [](const ReadableFolder* a, const ReadableFolder* b) {
    return a->path.native().size() > b->path.native().size();
  });
  // `from` where a path ends there (not /srv/data in /srv/data-old) replaced by `to`
  const auto replace_all = [&message](const std::string& from, const std::string& to) {
    for (std::size_t at = message.find(from); at != std::string::npos; at = message.find(from, at)) {
      const std::size_t end = at + from.size();
      const bool name_goes_on = from.back() != '/' && end < message.size() &&
                                (std::isalnum(static_cast<unsigned char>(message[end])) != 0 ||
                                 std::string_view("._-").find(message[end]) != std::string_view::npos);
      if (name_goes_on) {
        at = end;
        continue;
      }
      message.replace(at, from.size(), to);
      at += to.size();
    }
  };
  for (const ReadableFolder* f : longest_first) {
    // a file in the folder, then the folder itself
    replace_all((f->path / "").string(), f->label.empty() ? "" : f->label + "/");
    replace_all(f->path.string(), f->label.empty() ? "." : f->label);
  }
  return message;
}

}  // namespace uh
