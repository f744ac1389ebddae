#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <string>

#include "mesh_test_support.hpp"
#include "uh/collette/packing_preview.hpp"

namespace uh::collette {
namespace {

std::string read_all(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::string s(static_cast<std::size_t>(std::filesystem::file_size(p)), '\0');
  in.read(s.data(), static_cast<std::streamsize>(s.size()));
  return s;
}

std::uint32_t be32(const std::string& s, std::size_t at) {
  return (static_cast<std::uint32_t>(static_cast<unsigned char>(s[at])) << 24) |
         (static_cast<std::uint32_t>(static_cast<unsigned char>(s[at + 1])) << 16) |
         (static_cast<std::uint32_t>(static_cast<unsigned char>(s[at + 2])) << 8) |
         static_cast<std::uint32_t>(static_cast<unsigned char>(s[at + 3]));
}

std::vector<Sphere> some_spheres() {
  std::vector<Sphere> s;
  for (int i = 0; i < 5; ++i) {
    for (int j = 0; j < 5; ++j) s.push_back({0.3f * static_cast<float>(i), 0.3f * static_cast<float>(j), 0.f, 0.05f + 0.02f * static_cast<float>(i)});
  }
  return s;
}

TEST(PackingPreview, WritesAPngOfTheRequestedSize) {
  test::TempDir dir("preview");
  for (const bool section : {false, true}) {
    const auto path = dir / (section ? "section.png" : "full.png");
    const Status st = write_packing_preview(some_spheres(), path, {.width = 120, .height = 90, .section = section});
    ASSERT_TRUE(st) << st.error().message;
    const std::string png = read_all(path);
    ASSERT_GT(png.size(), 33u);
    EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
    EXPECT_EQ(png.substr(12, 4), "IHDR");
    EXPECT_EQ(be32(png, 16), 120u);
    EXPECT_EQ(be32(png, 20), 90u);
  }
  // nothing but the two pictures is left in the directory (no temporary files)
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), std::filesystem::directory_iterator()), 2);
}

TEST(PackingPreview, FailureKeepsTheExistingFile) {
  test::TempDir dir("preview_fail");
  const auto path = dir / "keep.png";
  { std::ofstream(path) << "previous picture"; }
  const Status bad_size = write_packing_preview(some_spheres(), path, {.width = 0});
  ASSERT_FALSE(bad_size);
  EXPECT_NE(bad_size.error().message.find("keep.png"), std::string::npos);
  EXPECT_EQ(read_all(path), "previous picture");
  const Status no_dir = write_packing_preview(some_spheres(), dir / "missing_dir" / "x.png");
  ASSERT_FALSE(no_dir);
  EXPECT_FALSE(std::filesystem::exists(dir / "missing_dir"));
}

}  // namespace
}  // namespace uh::collette
