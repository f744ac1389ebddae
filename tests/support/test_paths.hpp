#pragma once
// This build's paths for the tests: the committed assets, the uh program, the stand-in device
// libraries, the build's .ist cache. They are compiled into one generated source per build
// (tests/CMakeLists.txt, uh_test_paths) rather than passed as -D definitions to every test source,
// so that no other object file holds an absolute path and ccache reuses them in another clone.

namespace uh::test {
const char* data_dir();     // <source>/assets
const char* cache_dir();    // <build>/test-cache: .ist builds shared by the tests of one build
const char* cli_path();     // the uh program ("" in builds without it)
const char* standin_hd();   // tests/devices' stand-in libHD ("" where it is not built)
const char* standin_dhd();  // tests/devices' stand-in libdhd ("" where it is not built)
}  // namespace uh::test

#define UH_TEST_DATA_DIR (::uh::test::data_dir())
#define UH_TEST_CACHE_DIR (::uh::test::cache_dir())
#define UH_CLI_PATH (::uh::test::cli_path())
#define UH_STANDIN_HD (::uh::test::standin_hd())
#define UH_STANDIN_DHD (::uh::test::standin_dhd())
