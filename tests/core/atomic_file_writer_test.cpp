#include "uh/core/atomic_file_writer.hpp"

#include <gtest/gtest.h>

#include <fmt/format.h>
#include <sys/resource.h>
#include <unistd.h>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace uh {
namespace {

namespace fs = std::filesystem;

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class AtomicFileWriterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("uh_atomic_writer_test_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  // the files in dir_ other than `except`: a temporary left behind shows up here
  int other_files(const fs::path& except) const {
    int n = 0;
    for (const auto& e : fs::directory_iterator(dir_)) n += e.path() != except ? 1 : 0;
    return n;
  }
  fs::path dir_;
};

// writes beyond `bytes` fail with EFBIG (as on a full disk) while it lives; SIGXFSZ ignored
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    getrlimit(RLIMIT_FSIZE, &saved_);
    old_handler_ = std::signal(SIGXFSZ, SIG_IGN);
    rlimit limit = saved_;
    limit.rlim_cur = bytes;
    setrlimit(RLIMIT_FSIZE, &limit);
  }
  ~FileSizeLimit() {
    setrlimit(RLIMIT_FSIZE, &saved_);
    std::signal(SIGXFSZ, old_handler_);
  }

 private:
  rlimit saved_{};
  void (*old_handler_)(int) = nullptr;
};

TEST_F(AtomicFileWriterTest, WritesAndReplacesWholeFiles) {
  const fs::path target = dir_ / "out.csv";
  ASSERT_TRUE(write_file_atomically(target, "first\n"));
  EXPECT_EQ(read_text(target), "first\n");
  auto w = AtomicFileWriter::create(target);
  ASSERT_TRUE(w) << w.error().message;
  w->stream() << "second,";
  // nothing changes until the commit
  EXPECT_EQ(read_text(target), "first\n");
  for (int i = 0; i < 100000; ++i) w->stream() << i << ',';  // larger than the writer's buffer
  ASSERT_TRUE(w->commit());
  const std::string text = read_text(target);
  EXPECT_EQ(text.rfind("second,0,1,2,", 0), 0u);
  EXPECT_EQ(text.substr(text.size() - 6), "99999,");
  EXPECT_EQ(other_files(target), 0) << "the temporary file must be gone";
  EXPECT_FALSE(w->commit()) << "a second commit is refused";
}

TEST_F(AtomicFileWriterTest, AnAbandonedWriteChangesNothing) {
  const fs::path target = dir_ / "keep.ist";
  ASSERT_TRUE(write_file_atomically(target, "old content"));
  {
    auto w = AtomicFileWriter::create(target);
    ASSERT_TRUE(w);
    w->stream() << "half a file";
    EXPECT_EQ(other_files(target), 1) << "the temporary lies beside the target";
    AtomicFileWriter moved = std::move(*w);  // moving keeps one temporary, owned by `moved`
    moved.stream() << " and more";
  }
  EXPECT_EQ(read_text(target), "old content");
  EXPECT_EQ(other_files(target), 0);
}

TEST_F(AtomicFileWriterTest, AFailingWriteLeavesTheOldFileIntact) {
  const fs::path target = dir_ / "results.csv";
  const std::string old_content = "id,volume\na,1\n";
  ASSERT_TRUE(write_file_atomically(target, old_content));
  const std::string big(200000, 'x');
  Status st = Ok{};
  {
    const FileSizeLimit limit(4096);
    st = write_file_atomically(target, big);
  }
  ASSERT_FALSE(st);
  EXPECT_EQ(st.error().message, target.string() + ": write failed: File too large");
  EXPECT_EQ(read_text(target), old_content);
  EXPECT_EQ(other_files(target), 0) << "the temporary file must be removed";
  // and a write that fits still works afterwards
  ASSERT_TRUE(write_file_atomically(target, "new\n"));
  EXPECT_EQ(read_text(target), "new\n");
}

TEST_F(AtomicFileWriterTest, AFailingStreamWriteIsReportedByCommit) {
  const fs::path target = dir_ / "trace.csv";
  ASSERT_TRUE(write_file_atomically(target, "old"));
  auto w = AtomicFileWriter::create(target);
  ASSERT_TRUE(w);
  {
    const FileSizeLimit limit(1000);
    for (int i = 0; i < 20000; ++i) w->stream() << "0.001,0.002,0.003\n";
    w->stream().flush();
  }
  const Status st = w->commit();
  ASSERT_FALSE(st);
  EXPECT_NE(st.error().message.find("write failed"), std::string::npos) << st.error().message;
  EXPECT_EQ(read_text(target), "old");
  EXPECT_EQ(other_files(target), 0);
}

TEST_F(AtomicFileWriterTest, AMissingDirectoryIsAnErrorNamingTheTarget) {
  const fs::path target = dir_ / "no" / "such" / "dir" / "x.png";
  auto w = AtomicFileWriter::create(target);
  ASSERT_FALSE(w);
  EXPECT_EQ(w.error().message, fmt::format("{}: cannot create a file in {}: No such file or directory",
                                           target.string(), target.parent_path().string()));
  EXPECT_FALSE(write_file_atomically(target, "x"));
}

TEST_F(AtomicFileWriterTest, ARenameThatFailsLeavesTheTargetAndNoTemporary) {
  // the target is a non-empty directory: the final rename must fail, after all the writing
  const fs::path target = dir_ / "occupied";
  fs::create_directories(target / "inside");
  const Status st = write_file_atomically(target, "content");
  ASSERT_FALSE(st);
  EXPECT_NE(st.error().message.find("cannot move the finished file into place"), std::string::npos)
      << st.error().message;
  EXPECT_TRUE(fs::is_directory(target / "inside"));
  EXPECT_EQ(other_files(target), 0);
}

}  // namespace
}  // namespace uh
