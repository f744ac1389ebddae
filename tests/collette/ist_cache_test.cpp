#include "uh/collette/ist_cache.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <cstring>
#include <string>

#include <fmt/format.h>

#include "test_paths.hpp"
#include "uh/collette/ist_file.hpp"

namespace uh::collette {
namespace {

std::filesystem::path fresh_dir(const char* name) {
  const auto dir = std::filesystem::temp_directory_path() / fmt::format("uh-ist-cache-test-{}-{}", name, ::getpid());
  std::filesystem::remove_all(dir);
  return dir;
}

std::size_t files_in(const std::filesystem::path& dir) {
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir)) ++n;
  return n;
}

const std::filesystem::path kBall = std::filesystem::path(UH_TEST_DATA_DIR) / "meshes" / "ball.obj";

TEST(IstCache, BuildsOnceAndSharesTheTreeOfOneShape) {
  const auto dir = fresh_dir("share");
  IstCache cache(dir);
  int progress_calls = 0;
  const auto count = [&](const std::string&, double) { ++progress_calls; };
  const auto first = cache.mesh_tree(kBall, {.spheres = 120, .meters_per_unit = 0.01}, count);
  ASSERT_TRUE(first.has_value()) << first.error().message;
  EXPECT_GT(progress_calls, 0) << "the first request packs the mesh";
  EXPECT_EQ(files_in(dir), 1u) << "and caches its build";
  EXPECT_GT(first->coverage, 0.0);
  EXPECT_LE(first->coverage, 1.0);

  progress_calls = 0;
  const auto again = cache.mesh_tree(kBall, {.spheres = 120, .meters_per_unit = 0.01}, count);
  ASSERT_TRUE(again.has_value());
  EXPECT_EQ(again->tree.get(), first->tree.get()) << "one cache hands out one tree per shape";
  EXPECT_EQ(progress_calls, 0);

  // another cache of the same folder reads the build rather than packing again
  IstCache other(dir);
  const auto read = other.mesh_tree(kBall, {.spheres = 120, .meters_per_unit = 0.01}, count);
  ASSERT_TRUE(read.has_value());
  EXPECT_EQ(progress_calls, 0);
  EXPECT_NE(read->tree.get(), first->tree.get());
  EXPECT_EQ(read->tree->leaf_count(), first->tree->leaf_count());

  // another sphere count or scale is another shape
  const auto scaled = cache.mesh_tree(kBall, {.spheres = 120, .meters_per_unit = 0.02});
  ASSERT_TRUE(scaled.has_value());
  EXPECT_NE(scaled->tree.get(), first->tree.get());
  EXPECT_EQ(files_in(dir), 1u) << "the scale is not part of the packing";
  const auto finer = cache.mesh_tree(kBall, {.spheres = 200, .meters_per_unit = 0.01});
  ASSERT_TRUE(finer.has_value());
  EXPECT_EQ(files_in(dir), 2u);
  std::filesystem::remove_all(dir);
}

// A cache file written before the surface section (format 1) keeps its spheres and gains the mesh's
// surface on its next use, without packing again; the surface comes in metres, like the tree.
TEST(IstCache, AFormat1CacheFileGainsItsSurfaceWithoutPackingAgain) {
  const auto dir = fresh_dir("format1");
  const MeshPacking packing{.spheres = 120, .meters_per_unit = 0.01};
  {
    IstCache cache(dir);
    const auto built = cache.mesh_tree(kBall, packing);
    ASSERT_TRUE(built.has_value()) << built.error().message;
    EXPECT_NE(built->surface, nullptr) << "a packed mesh's cache file holds its surface";
  }
  ASSERT_EQ(files_in(dir), 1u);
  const std::filesystem::path cached = std::filesystem::directory_iterator(dir)->path();
  auto asset = load_ist(cached);
  ASSERT_TRUE(asset.has_value()) << asset.error().message;
  ASSERT_TRUE(asset->surface.has_value());
  asset->surface.reset();
  ASSERT_TRUE(save_ist(cached, *asset));  // as an older build wrote it: format 1

  IstCache cache(dir);
  int progress_calls = 0;
  const auto upgraded = cache.mesh_tree(kBall, packing, [&](const std::string&, double) { ++progress_calls; });
  ASSERT_TRUE(upgraded.has_value()) << upgraded.error().message;
  EXPECT_EQ(progress_calls, 0) << "not packed again";
  ASSERT_NE(upgraded->surface, nullptr);
  // in metres: the ball's surface lies around its spheres, within the packing's gap of them
  const SphereTreeNode& root = upgraded->tree->root();
  const Vec3 centre{static_cast<double>(root.x), static_cast<double>(root.y), static_cast<double>(root.z)};
  EXPECT_LT(upgraded->surface->signed_distance(centre), 0.0);
  EXPECT_LT(upgraded->surface->distance(centre), static_cast<double>(root.radius) + upgraded->max_gap_m + 1e-6);
  const auto rewritten = load_ist(cached);
  ASSERT_TRUE(rewritten.has_value()) << rewritten.error().message;
  EXPECT_TRUE(rewritten->surface.has_value()) << "written back with its surface";
  const auto now = rewritten->tree.leaves();
  const auto before = asset->tree.leaves();
  ASSERT_EQ(now.size(), before.size());
  EXPECT_EQ(std::memcmp(now.data(), before.data(), now.size_bytes()), 0) << "the same spheres";

  // a .ist file with a surface hands it out; one without, none
  const auto with = cache.ist_tree(cached);
  ASSERT_TRUE(with.has_value()) << with.error().message;
  EXPECT_NE(with->surface, nullptr);
  const auto bare = dir / "bare.ist";
  ASSERT_TRUE(save_ist(bare, *asset));
  const auto without = cache.ist_tree(bare);
  ASSERT_TRUE(without.has_value()) << without.error().message;
  EXPECT_EQ(without->surface, nullptr);
  std::filesystem::remove_all(dir);
}

TEST(IstCache, TheDefaultFolderFollowsTheEnvironment) {
  // this process's environment, put back as it was
  const char* before_uh = std::getenv("UH_CACHE_DIR");
  const char* before_xdg = std::getenv("XDG_CACHE_HOME");
  const std::string saved_uh = before_uh != nullptr ? before_uh : "";
  const std::string saved_xdg = before_xdg != nullptr ? before_xdg : "";
  ::setenv("UH_CACHE_DIR", "/tmp/uh-ist-cache-from-env", 1);
  EXPECT_EQ(IstCache::default_dir(), std::filesystem::path("/tmp/uh-ist-cache-from-env"));
  EXPECT_EQ(IstCache().dir(), std::filesystem::path("/tmp/uh-ist-cache-from-env"));
  ::unsetenv("UH_CACHE_DIR");
  ::setenv("XDG_CACHE_HOME", "/tmp/uh-xdg", 1);
  EXPECT_EQ(IstCache::default_dir(), std::filesystem::path("/tmp/uh-xdg") / "unrealhaptics");
  ::unsetenv("XDG_CACHE_HOME");
  if (before_uh != nullptr) ::setenv("UH_CACHE_DIR", saved_uh.c_str(), 1);
  if (before_xdg != nullptr) ::setenv("XDG_CACHE_HOME", saved_xdg.c_str(), 1);
}

}  // namespace
}  // namespace uh::collette
