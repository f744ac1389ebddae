#include "uh/core/atomic_file_writer.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <streambuf>
#include <string>
#include <utility>

namespace uh {

namespace {

// a stream buffer over a file descriptor that keeps the first write error (errno) instead of
// losing it inside an ofstream
class FdStreamBuf final : public std::streambuf {
 public:
  explicit FdStreamBuf(int fd) : fd_(fd) { setp(buffer_, buffer_ + sizeof(buffer_)); }
  int error() const { return error_; }

 protected:
  int_type overflow(int_type c) override {
    if (!drain()) return traits_type::eof();
    if (!traits_type::eq_int_type(c, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(c);
      pbump(1);
    }
    return traits_type::not_eof(c);
  }
  int sync() override { return drain() ? 0 : -1; }

 private:
  bool drain() {
    const char* p = pbase();
    std::size_t left = static_cast<std::size_t>(pptr() - pbase());
    while (left > 0 && error_ == 0) {
      const ssize_t w = ::write(fd_, p, left);
      if (w < 0) {
        if (errno == EINTR) continue;
        error_ = errno;
        break;
      }
      p += w;
      left -= static_cast<std::size_t>(w);
    }
    setp(buffer_, buffer_ + sizeof(buffer_));
    return error_ == 0;
  }

  int fd_;
  int error_ = 0;
  char buffer_[1 << 16];
};

std::string reason(int error) { return error != 0 ? std::strerror(error) : "unknown error"; }

}  // namespace

struct AtomicFileWriter::State {
  State(std::filesystem::path target_path, std::filesystem::path temp_path, int file)
      : target(std::move(target_path)), temp(std::move(temp_path)), fd(file), buf(file), out(&buf) {}
  std::filesystem::path target;
  std::filesystem::path temp;
  int fd;
  FdStreamBuf buf;
  std::ostream out;
  bool done = false;  // committed, or failed and cleaned up
};

Result<AtomicFileWriter> AtomicFileWriter::create(const std::filesystem::path& target) {
  const std::filesystem::path dir =
      target.has_parent_path() ? target.parent_path() : std::filesystem::path(".");
  // process id plus a per-process counter: concurrent writers never share a temporary file
  static std::atomic<unsigned> counter{0};
  const std::filesystem::path temp = dir / fmt::format(".{}.tmp{}-{}", target.filename().string(),
                                                       static_cast<long>(::getpid()), counter.fetch_add(1));
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) {
    return Error{
        fmt::format("{}: cannot create a file in {}: {}", target.string(), dir.string(), reason(errno))};
  }
  return AtomicFileWriter(std::make_unique<State>(target, temp, fd));
}

AtomicFileWriter::AtomicFileWriter(std::unique_ptr<State> state) : state_(std::move(state)) {}
AtomicFileWriter::AtomicFileWriter(AtomicFileWriter&&) noexcept = default;
AtomicFileWriter& AtomicFileWriter::operator=(AtomicFileWriter&& other) noexcept {
  if (this != &other) {
    AtomicFileWriter abandoned(std::move(*this));
    state_ = std::move(other.state_);
  }
  return *this;
}

AtomicFileWriter::~AtomicFileWriter() {
  if (state_ == nullptr || state_->done) return;
  ::close(state_->fd);
  ::unlink(state_->temp.c_str());
}

std::ostream& AtomicFileWriter::stream() { return state_->out; }

const std::filesystem::path& AtomicFileWriter::target() const { return state_->target; }

Status AtomicFileWriter::commit() {
  State& s = *state_;
  if (s.done) return Error{fmt::format("{}: already committed", s.target.string())};
  s.done = true;
  auto fail = [&](std::string_view what, int error) {
    ::unlink(s.temp.c_str());
    return Error{fmt::format("{}: {}: {}", s.target.string(), what, reason(error))};
  };
  s.out.flush();
  if (!s.out || s.buf.error() != 0) {
    ::close(s.fd);
    return fail("write failed", s.buf.error());
  }
  if (::fsync(s.fd) != 0) {
    const int e = errno;
    ::close(s.fd);
    return fail("write failed (fsync)", e);
  }
  if (::close(s.fd) != 0) return fail("write failed (close)", errno);
  if (::rename(s.temp.c_str(), s.target.c_str()) != 0)
    return fail("cannot move the finished file into place", errno);
  // the rename is durable only once the directory is: sync it (file systems that cannot sync a
  // directory say EINVAL; the rename has happened then, so that is no failure)
  const std::filesystem::path dir =
      s.target.has_parent_path() ? s.target.parent_path() : std::filesystem::path(".");
  const int dir_fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd >= 0) {
    const int synced = ::fsync(dir_fd);
    const int e = errno;
    ::close(dir_fd);
    if (synced != 0 && e != EINVAL) {
      return Error{fmt::format("{}: written, but its directory could not be synced: {}", s.target.string(),
                               reason(e))};
    }
  }
  return Ok{};
}

Status write_file_atomically(const std::filesystem::path& target, std::string_view bytes) {
  auto writer = AtomicFileWriter::create(target);
  if (!writer) return writer.error();
  writer->stream().write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return writer->commit();
}

}  // namespace uh
