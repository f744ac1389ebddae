#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "tree_test_support.hpp"
#include "uh/collette/ist_file.hpp"
#include "uh/collette/sphere_tree_builder.hpp"

namespace uh::collette {
namespace {

namespace fs = std::filesystem;

class IstFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("uh_ist_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    auto tree = build_sphere_tree(testing::make_packing(0.2, testing::Shape::kBall, 91));
    ASSERT_TRUE(tree);
    asset_.tree = std::move(*tree);
    asset_.meta = {.meters_per_unit = 0.001, .source_mesh_hash = 0x1234567890abcdefull, .coverage = 0.83,
                   .mesh_volume = 4.18, .max_gap = 0.05, .build_seconds = 1.5};
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string load_error(const std::vector<std::byte>& bytes) {
    const auto r = load_ist_from_memory(bytes, "x.ist");
    return r ? std::string() : r.error().message;
  }

  fs::path dir_;
  IstAsset asset_;
};

void write_bytes(const fs::path& p, const std::vector<std::byte>& b) {
  std::ofstream out(p, std::ios::binary);
  out.write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
}

TEST_F(IstFile, RoundTripKeepsEveryByte) {
  const fs::path p = dir_ / "ball.ist";
  ASSERT_TRUE(save_ist(p, asset_));
  const auto loaded = load_ist(p);
  ASSERT_TRUE(loaded) << loaded.error().message;
  const SphereTree& t = loaded->tree;
  ASSERT_EQ(t.node_count(), asset_.tree.node_count());
  ASSERT_EQ(t.leaf_count(), asset_.tree.leaf_count());
  EXPECT_EQ(t.depth(), asset_.tree.depth());
  EXPECT_EQ(t.arity(), asset_.tree.arity());
  EXPECT_EQ(std::memcmp(t.nodes().data(), asset_.tree.nodes().data(), t.nodes().size_bytes()), 0);
  EXPECT_EQ(std::memcmp(t.leaves().data(), asset_.tree.leaves().data(), t.leaves().size_bytes()), 0);
  EXPECT_EQ(loaded->meta.meters_per_unit, 0.001);
  EXPECT_EQ(loaded->meta.source_mesh_hash, 0x1234567890abcdefull);
  EXPECT_EQ(loaded->meta.coverage, 0.83);
  EXPECT_EQ(loaded->meta.mesh_volume, 4.18);
  EXPECT_EQ(loaded->meta.max_gap, 0.05);
  EXPECT_EQ(loaded->meta.build_seconds, 1.5);
  // saving again over an existing file replaces it and leaves no temporary behind
  ASSERT_TRUE(save_ist(p, asset_));
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir_)) files += e.is_regular_file() ? 1 : 0;
  EXPECT_EQ(files, 1);
}

TEST_F(IstFile, ChecksumsAndHashAreStandard) {
  const std::string text = "123456789";
  const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(text.data()), text.size());
  EXPECT_EQ(ist_crc32(bytes), 0xCBF43926u);                // the CRC-32 check value
  EXPECT_EQ(ist_hash_bytes(bytes), 0x06d5573923c6cdfcull);  // FNV-1a 64 of "123456789"
}

TEST_F(IstFile, MissingFileIsNamed) {
  const auto r = load_ist(dir_ / "nope.ist");
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("nope.ist"), std::string::npos) << r.error().message;
  EXPECT_NE(r.error().message.find("cannot open"), std::string::npos) << r.error().message;
}

TEST_F(IstFile, RejectsTruncatedFiles) {
  const auto bytes = encode_ist(asset_);
  for (std::size_t keep : {std::size_t{0}, std::size_t{5}, std::size_t{100}, kIstHeaderSize, bytes.size() / 2, bytes.size() - 1}) {
    std::vector<std::byte> cut(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(keep));
    const fs::path p = dir_ / "cut.ist";
    write_bytes(p, cut);
    const auto r = load_ist(p);
    ASSERT_FALSE(r) << "kept " << keep;
    if (keep == 0) {
      EXPECT_NE(r.error().message.find("not a .ist"), std::string::npos) << r.error().message;
    } else {
      EXPECT_NE(r.error().message.find("truncated"), std::string::npos) << "kept " << keep << ": " << r.error().message;
    }
    EXPECT_NE(r.error().message.find("cut.ist"), std::string::npos);
  }
}

TEST_F(IstFile, RejectsCorruptedForeignAndWrongVersion) {
  const auto bytes = encode_ist(asset_);
  // a flipped payload bit
  auto flipped = bytes;
  flipped[kIstHeaderSize + 37] ^= std::byte{0x10};
  EXPECT_NE(load_error(flipped).find("payload checksum"), std::string::npos) << load_error(flipped);
  // a flipped header bit (the node count)
  auto header = bytes;
  header[16] ^= std::byte{0x01};
  EXPECT_NE(load_error(header).find("header checksum"), std::string::npos) << load_error(header);
  // a foreign file
  std::vector<std::byte> obj;
  for (char c : std::string("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")) obj.push_back(static_cast<std::byte>(c));
  EXPECT_NE(load_error(obj).find("not a .ist"), std::string::npos) << load_error(obj);
  // a newer format version
  auto newer = bytes;
  newer[8] = std::byte{2};
  const std::string msg = load_error(newer);
  EXPECT_NE(msg.find("format version 2"), std::string::npos) << msg;
  EXPECT_NE(msg.find("version 1"), std::string::npos) << msg;
  // trailing garbage
  auto longer = bytes;
  longer.push_back(std::byte{0});
  EXPECT_NE(load_error(longer).find("unexpected bytes"), std::string::npos) << load_error(longer);
  EXPECT_EQ(load_error(bytes), "");
}

// Re-seals the checksums after an edit, as a hostile writer would, so the structural checks run.
void reseal(std::vector<std::byte>& b) {
  auto put = [&](std::size_t off, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) b[off + static_cast<std::size_t>(i)] = static_cast<std::byte>((v >> (8 * i)) & 0xffu);
  };
  put(96, ist_crc32({b.data() + kIstHeaderSize, b.size() - kIstHeaderSize}));
  put(100, ist_crc32({b.data(), 100}));
}

TEST_F(IstFile, RejectsHostileCountsAndTreesWithValidChecksums) {
  const auto bytes = encode_ist(asset_);
  // counts far beyond the file size must fail before any allocation of that size
  auto huge = bytes;
  for (std::size_t off : {std::size_t{16}, std::size_t{20}, std::size_t{80}}) {
    huge[off + 3] = std::byte{0x7f};
  }
  reseal(huge);
  EXPECT_NE(load_error(huge).find("corrupted"), std::string::npos) << load_error(huge);
  // a payload size that matches the counts but not the file
  auto big_payload = bytes;
  big_payload[88 + 4] = std::byte{1};
  reseal(big_payload);
  EXPECT_FALSE(load_error(big_payload).empty());
  // a child index pointing outside the node array
  auto bad_child = bytes;
  bad_child[kIstHeaderSize + 20] = std::byte{0xff};
  bad_child[kIstHeaderSize + 21] = std::byte{0xff};
  reseal(bad_child);
  EXPECT_NE(load_error(bad_child).find("invalid tree"), std::string::npos) << load_error(bad_child);
  // random byte edits with valid checksums never crash (ASan run) and never load silently wrong
  std::mt19937 rng(17);
  for (int k = 0; k < 300; ++k) {
    auto edited = bytes;
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int e = 0; e < edits; ++e) edited[8 + rng() % (edited.size() - 8)] = static_cast<std::byte>(rng() & 0xff);
    reseal(edited);
    const auto r = load_ist_from_memory(edited, "x.ist");
    if (r) {
      EXPECT_TRUE(validate(r->tree));
    }
  }
}

TEST_F(IstFile, SaveRefusesInvalidTreesAndUnwritablePaths) {
  IstAsset empty;
  const fs::path p = dir_ / "empty.ist";
  EXPECT_FALSE(save_ist(p, empty));
  EXPECT_FALSE(fs::exists(p));
  // a directory that does not exist: error names the file, nothing is created
  const auto r = save_ist(dir_ / "missing_dir" / "a.ist", asset_);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("a.ist"), std::string::npos);
  // a failed save does not clobber an existing good file
  const fs::path good = dir_ / "good.ist";
  ASSERT_TRUE(save_ist(good, asset_));
  EXPECT_FALSE(save_ist(good, empty));
  EXPECT_TRUE(load_ist(good));
}

}  // namespace
}  // namespace uh::collette
