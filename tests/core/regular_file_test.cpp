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

// A server's folders: inside by whole path components and after links and `..` are resolved;
// messages name files relative to the root and the cache by its label.
TEST_F(RegularFileTest, ReadableFoldersHoldWhatIsInsideAfterLinksAndDots) {
  const fs::path root = dir_ / "data", cache = dir_ / "cache", sibling = dir_ / "data-old";
  for (const fs::path& d : {root, cache, sibling}) fs::create_directories(d);
  fs::create_symlink(sibling / "secret.obj", root / "link.obj");
  const ReadableFolders folders({{.path = root, .label = ""}, {.path = cache, .label = "<cache>"}});
  EXPECT_TRUE(folders.check(root / "a.obj", "mesh"));
  EXPECT_TRUE(folders.check(root / "sub" / ".." / "a.obj", "mesh"));
  EXPECT_TRUE(folders.check(cache / "x.ist", "ist"));
  const auto refused = [&](const fs::path& p) {
    const Status s = folders.check(p, "mesh");
    return s ? std::string("accepted") : s.error().message;
  };
  EXPECT_EQ(
      refused(sibling / "secret.obj"),
      "mesh '../data-old/secret.obj' is outside the folders this server reads from (its root and its cache)");
  EXPECT_NE(refused(root / ".." / "data-old" / "a.obj").find("'../data-old/a.obj' is outside"),
            std::string::npos);
  EXPECT_NE(refused(root / "link.obj").find("'../data-old/secret.obj' is outside"), std::string::npos);
  EXPECT_NE(refused("/dev/zero").find("is outside"), std::string::npos);
  EXPECT_TRUE(ReadableFolders().check("/dev/zero", "mesh")) << "no folders: any path";
  EXPECT_EQ(folders.shown(fmt::format("{}: is a directory; {}: bad", (root / "m.obj").string(),
                                      (cache / "x.ist").string())),
            "m.obj: is a directory; <cache>/x.ist: bad");
  EXPECT_EQ(folders.shown(root.string() + ": is a directory"), ".: is a directory");
  EXPECT_EQ(folders.shown((sibling / "x.obj").string() + " and " + root.string()),
            (sibling / "x.obj").string() + " and .")
      << "a folder whose name starts with the root's is not the root";
}

TEST(JsonNesting, CountsArraysAndObjectsButNotBracketsInStrings) {
  EXPECT_EQ(json_nesting_depth("{}"), 1);
  EXPECT_EQ(json_nesting_depth(R"({"a": [[1], {"b": 2}]})"), 3);
  EXPECT_EQ(json_nesting_depth(R"({"a": "[[[[\"{{{"})"), 1);
  EXPECT_EQ(json_nesting_depth(std::string(100000, '[')), 100000);
}

}  // namespace
}  // namespace uh
