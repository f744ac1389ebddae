#include "uh/collette/ist_cache.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
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
