// The one reader of named files: only regular files, never a directory, FIFO or device, and never
// more than the caller's limit, each refusal naming the path and what is wrong.

#include "uh/core/regular_file.hpp"

#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <fmt/format.h>

#include "uh/core/json_nesting.hpp"

namespace uh {
namespace {

namespace fs = std::filesystem;

class RegularFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / fmt::format("uh-regular-file-test-{}", ::getpid());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  static void expect_refused(const fs::path& path, std::uint64_t limit, const std::string& what) {
    const auto read = read_regular_file(path, limit);
    ASSERT_FALSE(read.has_value()) << path;
    EXPECT_EQ(read.error().message.rfind(path.string() + ": ", 0), 0u) << read.error().message;
    EXPECT_NE(read.error().message.find(what), std::string::npos) << read.error().message;
    const auto checked = check_regular_file(path, limit);
    ASSERT_FALSE(checked.has_value()) << path;
    EXPECT_EQ(checked.error().message, read.error().message);
  }
  fs::path dir_;
};

TEST_F(RegularFileTest, ReadsARegularFileWithinItsLimit) {
  const fs::path file = dir_ / "scene.json";
  std::ofstream(file, std::ios::binary) << "{\"name\": \"x\"}";
  const auto text = read_regular_file(file, 13);
  ASSERT_TRUE(text.has_value()) << text.error().message;
  EXPECT_EQ(*text, "{\"name\": \"x\"}");
  EXPECT_EQ(check_regular_file(file, 13).value(), 13u);
  expect_refused(file, 12, "13 bytes is larger than the limit of 12 bytes");
  std::ofstream(dir_ / "empty", std::ios::binary).flush();
  EXPECT_EQ(read_regular_file(dir_ / "empty", 0).value(), "");
}

TEST_F(RegularFileTest, RefusesWhatIsNotARegularFile) {
  expect_refused(dir_, kMaxSceneFileBytes, "is a directory, not a file");
  expect_refused("/dev/zero", kMaxSceneFileBytes, "is a device, not a file");
  // a FIFO without a writer: refused at once, not waited on
  const fs::path fifo = dir_ / "pipe";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  expect_refused(fifo, kMaxSceneFileBytes, "is a FIFO (named pipe), not a file");
  expect_refused(dir_ / "missing.json", kMaxSceneFileBytes, "cannot open the file");
}

TEST_F(RegularFileTest, ASparseFileAboveTheLimitIsRefusedWithoutReadingIt) {
  const fs::path big = dir_ / "huge.obj";
  { std::ofstream(big, std::ios::binary).flush(); }
  fs::resize_file(big, std::uint64_t{2} << 30);  // 2 GiB of holes: nothing on the disk
  expect_refused(big, kMaxMeshFileBytes, "2147483648 bytes is larger than the limit of 1073741824 bytes");
}

TEST(JsonNesting, CountsArraysAndObjectsButNotBracketsInStrings) {
  EXPECT_EQ(json_nesting_depth("{}"), 1);
  EXPECT_EQ(json_nesting_depth(R"({"a": [[1], {"b": 2}]})"), 3);
  EXPECT_EQ(json_nesting_depth(R"({"a": "[[[[\"{{{"})"), 1);
  EXPECT_EQ(json_nesting_depth(std::string(100000, '[')), 100000);
}

}  // namespace
}  // namespace uh
