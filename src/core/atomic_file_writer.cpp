#include "uh/core/atomic_file_writer.hpp"

#include <fmt/format.h>
#include <atomic>
#include <streambuf>
#include <string>
#include <system_error>
#include <utility>

#include "file_ops.hpp"

namespace uh {

namespace {

// a stream buffer over a file descriptor that keeps the first write error instead of losing it
// inside an ofstream
class FdStreamBuf final : public std::streambuf {
 public:
  explicit FdStreamBuf(int fd) : fd_(fd) { setp(buffer_, buffer_ + sizeof(buffer_)); }
  std::error_code error() const { return error_; }

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
    if (!error_) error_ = detail::write_all(fd_, pbase(), static_cast<std::size_t>(pptr() - pbase()));
    setp(buffer_, buffer_ + sizeof(buffer_));
    return !error_;
  }

  int fd_;
  std::error_code error_;
  char buffer_[1 << 16];
};

std::string reason(std::error_code error) { return error ? error.message() : "unknown error"; }

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
                                                       detail::process_id(), counter.fetch_add(1));
  int fd = -1;
  if (const std::error_code error = detail::create_new_file(temp, fd)) {
    return Error{
        fmt::format("{}: cannot create a file in {}: {}", target.string(), dir.string(), reason(error)),
        ErrorKind::kFile};
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
  (void)detail::close_file(state_->fd);
  detail::remove_file(state_->temp);
}

std::ostream& AtomicFileWriter::stream() { return state_->out; }

const std::filesystem::path& AtomicFileWriter::target() const { return state_->target; }

Status AtomicFileWriter::commit() {
  State& s = *state_;
  if (s.done) return Error{fmt::format("{}: already committed", s.target.string())};
  s.done = true;
  auto fail = [&](std::string_view what, std::error_code error) {
    detail::remove_file(s.temp);
    return Error{fmt::format("{}: {}: {}", s.target.string(), what, reason(error)), ErrorKind::kFile};
  };
  s.out.flush();
  if (!s.out || s.buf.error()) {
    (void)detail::close_file(s.fd);
    return fail("write failed", s.buf.error());
  }
  if (const std::error_code error = detail::sync_file(s.fd)) {
    (void)detail::close_file(s.fd);
    return fail("write failed (fsync)", error);
  }
  if (const std::error_code error = detail::close_file(s.fd)) return fail("write failed (close)", error);
  if (const std::error_code error = detail::replace_file(s.temp, s.target))
    return fail("cannot move the finished file into place", error);
  // the rename is durable only once the directory is
  const std::filesystem::path dir =
      s.target.has_parent_path() ? s.target.parent_path() : std::filesystem::path(".");
  if (const std::error_code error = detail::sync_directory(dir)) {
    return Error{fmt::format("{}: written, but its directory could not be synced: {}", s.target.string(),
                             reason(error)),
                 ErrorKind::kFile};
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
