// The .ist's surface section (format version 2): the closed surface a packing's spheres were packed
// in, kept beside the tree so that a .ist alone gives the proxy a mesh to rest on. The packer writes
// it, it round-trips to the same bytes, a format 1 file (an older build's, checked in) still loads
// without one, and a truncated, corrupted or meaningless section is an error naming the file.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "mesh_test_support.hpp"
#include "test_paths.hpp"
#include "uh/collette/ist_builder.hpp"
#include "uh/collette/ist_file.hpp"
#include "uh/core/regular_file.hpp"

namespace uh::collette {
namespace {

namespace fs = std::filesystem;

// the unit cube packed with 40 spheres by the packer, which keeps the cube as the surface
IstAsset packed_cube() {
  auto cube = validate_mesh(test::unit_cube());
  EXPECT_TRUE(cube) << cube.error().message;
  auto built = build_ist_asset(*cube, 0x42, {.sphere_count = 40});
  EXPECT_TRUE(built) << built.error().message;
  return std::move(built->asset);
}

std::string file_text(const fs::path& p) {
  auto text = read_regular_file(p, 1 << 20);
  EXPECT_TRUE(text) << text.error().message;
  return text ? *text : std::string();
}

std::uint32_t u32_at(const std::vector<std::byte>& b, std::size_t offset) {
  std::uint32_t v = 0;
  for (std::size_t i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(b[offset + i]) << (8 * i);
  return v;
}

void put_u32_at(std::vector<std::byte>& b, std::size_t offset, std::uint32_t v) {
  for (std::size_t i = 0; i < 4; ++i) b[offset + i] = static_cast<std::byte>((v >> (8 * i)) & 0xffu);
}

// where the surface section starts: after the header and the tree's nodes and leaves
std::size_t surface_offset(const IstAsset& a) {
  return kIstHeaderSize + 32 * static_cast<std::size_t>(a.tree.node_count()) +
         16 * static_cast<std::size_t>(a.tree.leaf_count());
}

// the section's closing checksum sealed again after an edit, as a hostile writer would
void reseal_surface(std::vector<std::byte>& b, std::size_t start) {
  put_u32_at(b, b.size() - 4, ist_crc32({b.data() + start, b.size() - 4 - start}));
}

class IstSurface : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           fmt::format("uh-ist-surface-test-{}-{}", ::getpid(),
                       ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // the error of loading `bytes` from a file called `name` in the test's folder ("" when it loads)
  std::string file_error(const std::vector<std::byte>& bytes, const std::string& name) {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    const auto r = load_ist(p);
    return r ? std::string() : r.error().message;
  }

  fs::path dir_;
  const IstAsset cube_ = packed_cube();
};

TEST_F(IstSurface, ThePackerKeepsTheSurfaceAndItRoundTripsAsVersion2) {
  ASSERT_TRUE(cube_.surface.has_value());
  const TriangleMesh reference = *validate_mesh(test::unit_cube());
  EXPECT_EQ(cube_.surface->vertices, reference.vertices);
  EXPECT_EQ(cube_.surface->triangles, reference.triangles);

  const fs::path p = dir_ / "cube.ist";
  ASSERT_TRUE(save_ist(p, cube_));
  const std::string text = file_text(p);
  std::vector<std::byte> bytes(text.size());
  std::memcpy(bytes.data(), text.data(), text.size());
  EXPECT_EQ(u32_at(bytes, 8), 2u) << "format version";
  EXPECT_EQ(u32_at(bytes, 84), kIstFlagSurface) << "flags";
  // the section: counts, 24 bytes a vertex, 12 a triangle, its checksum
  EXPECT_EQ(bytes.size(), surface_offset(cube_) + 8 + 24 * 8 + 12 * 12 + 4);

  const auto loaded = load_ist(p);
  ASSERT_TRUE(loaded) << loaded.error().message;
  ASSERT_TRUE(loaded->surface.has_value());
  EXPECT_EQ(loaded->surface->vertices, reference.vertices);
  EXPECT_EQ(loaded->surface->triangles, reference.triangles);
  EXPECT_EQ(encode_ist(*loaded), bytes) << "whatever loads re-encodes to the same bytes";

  // without a surface the asset is written as format 1, which older builds read
  IstAsset bare{cube_.tree, cube_.meta};
  const auto v1 = encode_ist(bare);
  EXPECT_EQ(u32_at(v1, 8), 1u);
  EXPECT_EQ(u32_at(v1, 84), 0u);
  EXPECT_EQ(v1.size(), surface_offset(cube_));
}

TEST_F(IstSurface, AFormat1FileStillLoadsWithoutASurface) {
  // written by the build before format 2: `uh ist build assets/meshes/slab.obj --spheres 300
  // --meters-per-unit 0.01`
  const fs::path p = fs::path(UH_TEST_DATA_DIR) / "ist" / "slab_format1.ist";
  const std::string text = file_text(p);
  ASSERT_GT(text.size(), kIstHeaderSize) << p;
  EXPECT_EQ(text[8], 1) << "a format 1 file";
  const auto loaded = load_ist(p);
  ASSERT_TRUE(loaded) << loaded.error().message;
  EXPECT_FALSE(loaded->surface.has_value());
  EXPECT_EQ(loaded->tree.leaf_count(), 300);
  EXPECT_DOUBLE_EQ(loaded->meta.meters_per_unit, 0.01);
  const auto again = encode_ist(*loaded);
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(again.data()), again.size()), text)
      << "format 1 is written as it was";
}

TEST_F(IstSurface, ATruncatedOrCorruptSurfaceSectionIsAnErrorNamingTheFile) {
  const auto bytes = encode_ist(cube_);
  const std::size_t start = surface_offset(cube_);
  for (const std::size_t keep : {start, start + 4, start + 8 + 50, bytes.size() - 1}) {
    const std::vector<std::byte> cut(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(keep));
    const std::string msg = file_error(cut, "cut.ist");
    EXPECT_NE(msg.find("cut.ist: truncated"), std::string::npos) << "kept " << keep << ": " << msg;
  }
  auto flipped = bytes;
  flipped[start + 8 + 3] ^= std::byte{0x10};  // a bit of the first vertex
  EXPECT_NE(
      file_error(flipped, "flipped.ist").find("flipped.ist: corrupted: surface section checksum mismatch"),
      std::string::npos)
      << file_error(flipped, "flipped.ist");
  auto longer = bytes;
  longer.push_back(std::byte{0});
  EXPECT_NE(file_error(longer, "long.ist").find("1 unexpected bytes after the surface section"),
            std::string::npos)
      << file_error(longer, "long.ist");
  // counts no closed surface has, sealed again: refused before anything of that size is allocated
  for (const auto& [vertices, triangles] :
       {std::pair{1000000u, 12u}, std::pair{8u, 0x40000000u}, std::pair{2u, 12u}}) {
    auto counted = bytes;
    put_u32_at(counted, start, vertices);
    put_u32_at(counted, start + 4, triangles);
    reseal_surface(counted, start);
    const std::string msg = file_error(counted, "counts.ist");
    EXPECT_NE(
        msg.find("counts.ist: corrupted: a surface section of " + std::to_string(vertices) + " vertices"),
        std::string::npos)
        << msg;
  }
  // a version 2 header whose flags do not announce the surface (header checksum sealed again)
  for (const std::uint32_t flags : {0u, 3u}) {
    auto flagged = bytes;
    put_u32_at(flagged, 84, flags);
    put_u32_at(flagged, 100, ist_crc32({flagged.data(), 100}));
    const std::string msg = file_error(flagged, "flags.ist");
    EXPECT_NE(
        msg.find("flags.ist: corrupted: flags " + std::to_string(flags) + " (format version 2 expects 1"),
        std::string::npos)
        << msg;
  }
  EXPECT_EQ(file_error(bytes, "good.ist"), "");
}

TEST_F(IstSurface, AMeaninglessSurfaceIsRefusedWithValidChecksums) {
  struct Case {
    const char* what;
    void (*edit)(TriangleMesh&);
    std::string expected;
  };
  const std::vector<Case> cases{
      {"one triangle turned", [](TriangleMesh& m) { std::swap(m.triangles[3][1], m.triangles[3][2]); },
       "orientation is inconsistent"},
      {"every triangle turned",
       [](TriangleMesh& m) {
         for (auto& t : m.triangles) std::swap(t[1], t[2]);
       },
       "wound inside out"},
      {"a triangle missing", [](TriangleMesh& m) { m.triangles.pop_back(); }, "not closed"},
      {"a corner beyond the vertices", [](TriangleMesh& m) { m.triangles[0][1] = 8; }, "refers to vertex 8"},
      {"a NaN coordinate", [](TriangleMesh& m) { m.vertices[2].y = std::nan(""); }, "non-finite"},
      {"a vertex no triangle uses",
       [](TriangleMesh& m) {
         m.vertices.push_back({0.5, 0.5, 0.5});
       },
       "has one no triangle uses"},
      {"twice the size",
       [](TriangleMesh& m) {
         for (Vec3& v : m.vertices) v = 2.0 * v - Vec3{0.5, 0.5, 0.5};
       },
       "it encloses 8, but mesh_volume is 1"},
      {"moved off the spheres",
       [](TriangleMesh& m) {
         for (Vec3& v : m.vertices) v.x += 0.5;
       },
       "reaches outside the surface's bounding box"},
  };
  for (const Case& c : cases) {
    IstAsset edited{cube_.tree, cube_.meta, cube_.surface};
    c.edit(*edited.surface);
    const std::string msg = file_error(encode_ist(edited), "bad.ist");
    EXPECT_NE(msg.find("/bad.ist: invalid surface section"), std::string::npos) << c.what << ": " << msg;
    EXPECT_NE(msg.find(c.expected), std::string::npos) << c.what << ": " << msg;
    // and such an asset is never written
    const auto saved = save_ist(dir_ / "refused.ist", edited);
    ASSERT_FALSE(saved) << c.what;
    EXPECT_NE(saved.error().message.find("refused.ist: not saved: invalid surface section"),
              std::string::npos)
        << c.what << ": " << saved.error().message;
    EXPECT_FALSE(fs::exists(dir_ / "refused.ist"));
  }
}

}  // namespace
}  // namespace uh::collette
