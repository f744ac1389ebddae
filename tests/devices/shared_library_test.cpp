#include "uh/devices/shared_library.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "dhd_standin_control.hpp"

namespace uh::devices {
namespace {

using haptico::DeviceConfig;

const LibrarySearch kSearch{.vendor = "Example SDK",
                            .environment_variable = "UH_EXAMPLE_LIBRARY",
                            .install_names = {"libuh-example-missing.so", "/nonexistent/libuh-example.so"}};

TEST(SharedLibrary, LoadsAFileAndBindsItsFunctions) {
  testing::DhdStandin standin;  // resets the stand-in: one device
  auto library = SharedLibrary::load(testing::DhdStandin::path());
  ASSERT_TRUE(library) << library.error().message;
  EXPECT_EQ(library->path(), testing::DhdStandin::path());
  int (*count)() = nullptr;
  ASSERT_TRUE(library->bind(count, "dhdGetDeviceCount"));
  EXPECT_EQ(count(), 1);
  // one instance per file: the script set through another handle is seen here
  standin.set("devices", 3);
  EXPECT_EQ(count(), 3);
}

TEST(SharedLibrary, AMissingSymbolNamesTheLibraryAndTheSymbol) {
  auto library = SharedLibrary::load(testing::DhdStandin::path());
  ASSERT_TRUE(library);
  void (*fn)() = nullptr;
  const Status bound = library->bind(fn, "dhdNoSuchFunction");
  ASSERT_FALSE(bound);
  EXPECT_NE(bound.error().message.find(testing::DhdStandin::path()), std::string::npos)
      << bound.error().message;
  EXPECT_NE(bound.error().message.find("does not export dhdNoSuchFunction"), std::string::npos);
  EXPECT_EQ(fn, nullptr);
}

TEST(SharedLibrary, MovingHandsTheLibraryOver) {
  auto library = SharedLibrary::load(testing::DhdStandin::path());
  ASSERT_TRUE(library);
  SharedLibrary moved = std::move(library).value();
  EXPECT_TRUE(moved.loaded());
  EXPECT_NE(moved.symbol("dhdSetForce"), nullptr);
  SharedLibrary other;
  EXPECT_FALSE(other.loaded());
  EXPECT_EQ(other.symbol("dhdSetForce"), nullptr);
  other = std::move(moved);
  EXPECT_TRUE(other.loaded());
  EXPECT_FALSE(moved.loaded());  // NOLINT(bugprone-use-after-move): the moved-from state is specified
}

TEST(LibrarySearch, TheConfigThenTheEnvironmentThenTheInstallNames) {
  ::unsetenv("UH_EXAMPLE_LIBRARY");
  auto install = library_candidates(kSearch, {});
  ASSERT_EQ(install.size(), 2u);
  EXPECT_EQ(install[0].path, "libuh-example-missing.so");
  EXPECT_EQ(install[1].origin, "the vendor's install name");

  ::setenv("UH_EXAMPLE_LIBRARY", "/from/env/libx.so", 1);
  auto env = library_candidates(kSearch, {});
  ASSERT_EQ(env.size(), 1u);
  EXPECT_EQ(env[0].path, "/from/env/libx.so");
  EXPECT_EQ(env[0].origin, "UH_EXAMPLE_LIBRARY");

  // an explicit choice is never replaced by another library
  auto config = library_candidates(kSearch, DeviceConfig{{"library", "/from/config/libx.so"}});
  ASSERT_EQ(config.size(), 1u);
  EXPECT_EQ(config[0].path, "/from/config/libx.so");
  EXPECT_EQ(config[0].origin, "tool.device.config.library");
  ::unsetenv("UH_EXAMPLE_LIBRARY");
}

TEST(LibrarySearch, FailingListsEveryPlaceTriedAndEveryPlaceNotSet) {
  ::unsetenv("UH_EXAMPLE_LIBRARY");
  auto none = SharedLibrary::load_first(kSearch, {});
  ASSERT_FALSE(none);
  const std::string& m = none.error().message;
  EXPECT_EQ(m.rfind("could not load the Example SDK library; tried:", 0), 0u) << m;
  EXPECT_NE(m.find("libuh-example-missing.so (from the vendor's install name): "), std::string::npos) << m;
  EXPECT_NE(m.find("/nonexistent/libuh-example.so (from the vendor's install name): "), std::string::npos)
      << m;
  EXPECT_NE(m.find("tool.device.config.library is not set"), std::string::npos) << m;
  EXPECT_NE(m.find("the environment variable UH_EXAMPLE_LIBRARY is not set"), std::string::npos) << m;

  auto configured = SharedLibrary::load_first(kSearch, DeviceConfig{{"library", "/nonexistent/libdhd.so"}});
  ASSERT_FALSE(configured);
  EXPECT_NE(configured.error().message.find("/nonexistent/libdhd.so (from tool.device.config.library): "),
            std::string::npos)
      << configured.error().message;
  EXPECT_EQ(configured.error().message.find("install name"), std::string::npos) << configured.error().message;

  auto found = SharedLibrary::load_first(kSearch, DeviceConfig{{"library", testing::DhdStandin::path()}});
  ASSERT_TRUE(found) << found.error().message;
  EXPECT_EQ(found->path(), testing::DhdStandin::path());
}

}  // namespace
}  // namespace uh::devices
