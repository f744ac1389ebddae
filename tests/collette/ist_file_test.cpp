#include <gtest/gtest.h>

#include <cmath>
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
    asset_.meta = {.meters_per_unit = 0.001,
                   .source_mesh_hash = 0x1234567890abcdefull,
                   .coverage = 0.83,
                   .mesh_volume = asset_.tree.total_volume() / 0.83,
                   .max_gap = 0.05,
                   .build_seconds = 1.5};
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
  EXPECT_EQ(loaded->meta.mesh_volume, asset_.meta.mesh_volume);
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
  EXPECT_EQ(ist_crc32(bytes), 0xCBF43926u);                 // the CRC-32 check value
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
  for (std::size_t keep : {std::size_t{0}, std::size_t{5}, std::size_t{100}, kIstHeaderSize, bytes.size() / 2,
                           bytes.size() - 1}) {
    std::vector<std::byte> cut(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(keep));
    const fs::path p = dir_ / "cut.ist";
    write_bytes(p, cut);
    const auto r = load_ist(p);
    ASSERT_FALSE(r) << "kept " << keep;
    if (keep == 0) {
      EXPECT_NE(r.error().message.find("not a .ist"), std::string::npos) << r.error().message;
    } else {
      EXPECT_NE(r.error().message.find("truncated"), std::string::npos)
          << "kept " << keep << ": " << r.error().message;
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
  newer[8] = std::byte{3};
  const std::string msg = load_error(newer);
  EXPECT_NE(msg.find("format version 3"), std::string::npos) << msg;
  EXPECT_NE(msg.find("versions 1 to 2"), std::string::npos) << msg;
  // trailing garbage
  auto longer = bytes;
  longer.push_back(std::byte{0});
  EXPECT_NE(load_error(longer).find("unexpected bytes"), std::string::npos) << load_error(longer);
  EXPECT_EQ(load_error(bytes), "");
}

// Re-seals the checksums after an edit, as a hostile writer would, so the structural checks run.
void reseal(std::vector<std::byte>& b) {
  auto put = [&](std::size_t off, std::uint32_t v) {
    for (int i = 0; i < 4; ++i)
      b[off + static_cast<std::size_t>(i)] = static_cast<std::byte>((v >> (8 * i)) & 0xffu);
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
    for (int e = 0; e < edits; ++e)
      edited[8 + rng() % (edited.size() - 8)] = static_cast<std::byte>(rng() & 0xff);
    reseal(edited);
    const auto r = load_ist_from_memory(edited, "x.ist");
    if (r) {
      EXPECT_TRUE(validate(r->tree));
      EXPECT_TRUE(validate(*r));
    }
  }
}

// An asset edited in memory, encoded with valid checksums: only the semantic checks can refuse it.
struct Parts {
  std::vector<SphereTreeNode> nodes;
  std::vector<Sphere> leaves;
  int depth;
  int arity;
  IstMetadata meta;
};
template <typename Edit>
std::vector<std::byte> encode_edited(const IstAsset& a, Edit edit) {
  Parts p{{a.tree.nodes().begin(), a.tree.nodes().end()},
          {a.tree.leaves().begin(), a.tree.leaves().end()},
          a.tree.depth(),
          a.tree.arity(),
          a.meta};
  edit(p);
  return encode_ist(IstAsset{SphereTree(std::move(p.nodes), std::move(p.leaves), p.depth, p.arity), p.meta});
}

// A two-leaf asset with the leaves `gap` apart (negative: overlapping), metadata consistent.
IstAsset two_leaves(float gap) {
  const std::vector<Sphere> leaves{{0.f, 0.f, 0.f, 1.f}, {2.f + gap, 0.f, 0.f, 1.f}};
  auto tree = build_sphere_tree(leaves);
  EXPECT_TRUE(tree);
  IstAsset a{std::move(*tree), {}};
  a.meta = {.coverage = 0.5, .mesh_volume = a.tree.total_volume() / 0.5};
  return a;
}

TEST_F(IstFile, RejectsEveryMeaninglessFieldWithValidChecksums) {
  struct Case {
    const char* what;
    std::vector<std::byte> bytes;
    std::vector<std::string> expected;  // all must appear in the message
  };
  const double nan = std::nan("");
  const double inf = HUGE_VAL;
  auto meta = [&](auto edit) { return encode_edited(asset_, [&](Parts& p) { edit(p.meta); }); };
  std::size_t leaf_node = 0;
  while (!asset_.tree.nodes()[leaf_node].is_leaf()) ++leaf_node;
  const std::size_t inner = static_cast<std::size_t>(asset_.tree.root().first);
  std::vector<Case> cases{
      {"negative units", meta([](IstMetadata& m) { m.meters_per_unit = -1.0; }), {"meters_per_unit is -1"}},
      {"NaN units", meta([&](IstMetadata& m) { m.meters_per_unit = nan; }), {"meters_per_unit is nan"}},
      {"zero units", meta([](IstMetadata& m) { m.meters_per_unit = 0.0; }), {"meters_per_unit is 0"}},
      {"infinite units", meta([&](IstMetadata& m) { m.meters_per_unit = inf; }), {"meters_per_unit is inf"}},
      {"denormal units",
       meta([](IstMetadata& m) { m.meters_per_unit = 1e-300; }),
       {"meters_per_unit is 1e-300"}},
      {"NaN mesh volume", meta([&](IstMetadata& m) { m.mesh_volume = nan; }), {"mesh_volume is nan"}},
      {"negative mesh volume", meta([](IstMetadata& m) { m.mesh_volume = -4.0; }), {"mesh_volume is -4"}},
      {"NaN coverage", meta([&](IstMetadata& m) { m.coverage = nan; }), {"coverage is nan"}},
      {"zero coverage", meta([](IstMetadata& m) { m.coverage = 0.0; }), {"coverage is 0", "(0, 1]"}},
      {"coverage above one", meta([](IstMetadata& m) { m.coverage = 1.5; }), {"coverage is 1.5"}},
      {"coverage that does not match the volumes",
       meta([](IstMetadata& m) { m.coverage = 0.5; }),
       {"coverage is 0.5", "mesh_volume"}},
      {"mesh smaller than its spheres",
       meta([&](IstMetadata& m) {
         m.mesh_volume = 0.5 * asset_.tree.total_volume();
         m.coverage = 1.0;
       }),
       {"coverage is 1"}},
      {"NaN max gap", meta([&](IstMetadata& m) { m.max_gap = nan; }), {"max_gap is nan"}},
      {"negative max gap", meta([](IstMetadata& m) { m.max_gap = -0.1; }), {"max_gap is -0.1"}},
      {"negative build time", meta([](IstMetadata& m) { m.build_seconds = -1.0; }), {"build_seconds is -1"}},
      {"infinite build time", meta([&](IstMetadata& m) { m.build_seconds = inf; }), {"build_seconds is inf"}},
      {"negative leaf radius",
       encode_edited(asset_,
                     [&](Parts& p) {
                       p.nodes[leaf_node].radius = -p.nodes[leaf_node].radius;
                       p.leaves[static_cast<std::size_t>(p.nodes[leaf_node].first)].radius =
                           p.nodes[leaf_node].radius;
                     }),
       {"invalid tree", "radius", "not positive"}},
      {"NaN leaf centre",
       encode_edited(asset_,
                     [&](Parts& p) {
                       p.nodes[leaf_node].x = std::nanf("");
                       p.leaves[static_cast<std::size_t>(p.nodes[leaf_node].first)].x = std::nanf("");
                     }),
       {"invalid tree", "non-finite"}},
      {"root not enclosing its children",
       encode_edited(asset_, [](Parts& p) { p.nodes[0].radius *= 0.9f; }),
       {"invalid tree", "node 0", "does not enclose"}},
      {"inner node not enclosing its leaves",
       // moved by twice its radius: every leaf below is then outside it, however loose the sphere
       encode_edited(asset_, [&](Parts& p) { p.nodes[inner].x += 2.f * p.nodes[inner].radius; }),
       {"invalid tree", "does not enclose"}},
      {"node volume not the sum",
       encode_edited(asset_, [&](Parts& p) { p.nodes[inner].volume *= 1.01f; }),
       {"invalid tree", "not the sum"}},
      {"arity below a node's child count",
       encode_edited(asset_, [](Parts& p) { p.arity = 2; }),
       {"invalid tree", "more children than the arity 2"}},
      {"wrong depth", encode_edited(asset_, [](Parts& p) { p.depth += 1; }), {"invalid tree", "depth"}},
      {"overlapping leaves",
       encode_ist(two_leaves(-0.01f)),
       {"invalid tree", "leaf spheres 0 and 1 overlap"}},
      {"a leaf too small for its position",
       encode_edited(asset_,
                     [&](Parts& p) {
                       // radius 1e-12 at a centre ~0.5 from the origin (ratio below 1e-9); volumes kept
                       // consistent
                       auto& n = p.nodes[leaf_node];
                       auto& leaf = p.leaves[static_cast<std::size_t>(n.first)];
                       const float before = n.volume;
                       n.radius = leaf.radius = 1e-12f;
                       n.volume = static_cast<float>(4.0 / 3.0 * kPi * 1e-36);
                       for (int q = n.parent; q >= 0; q = p.nodes[static_cast<std::size_t>(q)].parent)
                         p.nodes[static_cast<std::size_t>(q)].volume -= before;
                       p.meta.mesh_volume = static_cast<double>(p.nodes[0].volume) / p.meta.coverage;
                     }),
       {"leaf sphere", "below 1e-9"}},
  };
  for (const Case& c : cases) {
    const std::string msg = load_error(c.bytes);
    ASSERT_FALSE(msg.empty()) << c.what << " loaded";
    EXPECT_EQ(msg.find("checksum"), std::string::npos) << c.what << ": " << msg;
    EXPECT_EQ(msg.rfind("x.ist: ", 0), 0u) << c.what << ": " << msg;
    for (const std::string& e : c.expected)
      EXPECT_NE(msg.find(e), std::string::npos) << c.what << ": " << msg;
  }
}

TEST_F(IstFile, RejectsFlagsAndReservedBytes) {
  auto flags = encode_ist(asset_);
  flags[84] = std::byte{1};
  reseal(flags);
  EXPECT_NE(load_error(flags).find("flags 1"), std::string::npos) << load_error(flags);
  // the reserved bytes lie outside the header checksum, so no reseal is needed to reach the check
  auto reserved = encode_ist(asset_);
  reserved[117] = std::byte{7};
  EXPECT_NE(load_error(reserved).find("reserved header byte 117"), std::string::npos) << load_error(reserved);
}

TEST_F(IstFile, LeafOverlapToleranceIsTheDocumentedOne) {
  // root radius ~2: tolerance 2e-5; a float step at 2.0 is 2.4e-7
  EXPECT_EQ(load_error(encode_ist(two_leaves(0.f))), "");
  EXPECT_EQ(load_error(encode_ist(two_leaves(-1e-5f))), "");
  EXPECT_NE(load_error(encode_ist(two_leaves(-4e-5f))).find("overlap"), std::string::npos);
}

TEST_F(IstFile, OverlapCheckMatchesAllPairsOnMixedRadii) {
  // spheres of radii over five octaves, some pairs nudged into overlap: the grid check finds an
  // overlap exactly when the all-pairs loop does
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int overlapping = 0;
  for (int trial = 0; trial < 40; ++trial) {
    std::vector<Sphere> leaves;
    for (int i = 0; i < 30; ++i) {
      const double r = 0.01 * std::pow(2.0, 5.0 * u(rng));
      leaves.push_back({static_cast<float>(4 * u(rng)), static_cast<float>(4 * u(rng)),
                        static_cast<float>(u(rng)), static_cast<float>(r)});
    }
    auto tree = build_sphere_tree(leaves);
    ASSERT_TRUE(tree);
    IstAsset a{std::move(*tree), {}};
    a.meta = {.coverage = 0.5, .mesh_volume = a.tree.total_volume() / 0.5};
    const double tol = 1e-5 * static_cast<double>(a.tree.root().radius);
    bool overlap = false;
    for (std::size_t i = 0; i < leaves.size(); ++i)
      for (std::size_t j = i + 1; j < leaves.size(); ++j) {
        const double d = norm(testing::centre(leaves[i]) - testing::centre(leaves[j]));
        overlap = overlap ||
                  static_cast<double>(leaves[i].radius) + static_cast<double>(leaves[j].radius) - d > tol;
      }
    const Status ok = validate(a);
    EXPECT_EQ(!ok, overlap) << "trial " << trial << ": " << (ok ? "valid" : ok.error().message);
    overlapping += overlap ? 1 : 0;
  }
  // both outcomes occur, so the comparison means something
  EXPECT_GT(overlapping, 5);
  EXPECT_LT(overlapping, 35);
}

TEST_F(IstFile, SaveRefusesMeaninglessMetadata) {
  IstAsset bad{asset_.tree, asset_.meta};
  bad.meta.meters_per_unit = std::nan("");
  const fs::path p = dir_ / "nan_units.ist";
  const auto r = save_ist(p, bad);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("meters_per_unit"), std::string::npos) << r.error().message;
  EXPECT_FALSE(fs::exists(p));
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
