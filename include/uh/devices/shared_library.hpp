#pragma once
/// \file
/// SharedLibrary: a vendor library loaded at run time, and the search for it.

#include <bit>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "uh/core/result.hpp"
#include "uh/haptico/device_config.hpp"

namespace uh::devices {

/// One place a driver looks for its vendor library.
struct LibraryCandidate {
  std::string path;    ///< a file path, or a bare file name the system loader searches for
  std::string origin;  ///< where the path came from, for messages: "tool.device.config.library", ...
};

/// Where a driver finds its vendor library (aggregate): the device config's `library` if given,
/// else the environment variable if set, else the vendor's usual install names, in order.
struct LibrarySearch {
  std::string vendor;                      ///< for messages, e.g. "Force Dimension DHD"
  std::string environment_variable;        ///< e.g. "UH_FORCEDIMENSION_LIBRARY"
  std::vector<std::string> install_names;  ///< e.g. {"libdhd.so", "libdhd.so.3"}
};

/// The places to try for `search` given a driver's `config`: only the config's `library` when it is
/// set (an explicit choice is never replaced by another library), else only the environment
/// variable's value when it is set, else the install names. Setup only.
std::vector<LibraryCandidate> library_candidates(const LibrarySearch& search,
                                                 const haptico::DeviceConfig& config);

/// A shared library loaded into the process, unloaded by the destructor (RAII, move only).
/// Function addresses from symbol() / bind() are valid while it lives.
///
/// The loader itself lives in one platform file (shared_library_posix.cpp: dlopen, dlsym); a
/// Windows build adds its LoadLibrary counterpart beside it, nothing else changes.
///
/// Threads: setup only (load, bind, unload on one thread); calling the bound functions follows the
/// vendor's rules.
class SharedLibrary {
 public:
  SharedLibrary() = default;
  ~SharedLibrary();
  SharedLibrary(SharedLibrary&& other) noexcept;
  SharedLibrary& operator=(SharedLibrary&& other) noexcept;
  SharedLibrary(const SharedLibrary&) = delete;
  SharedLibrary& operator=(const SharedLibrary&) = delete;

  /// Loads `path` (all symbols resolved now, none exported to other libraries); an Error with the
  /// system loader's message.
  static Result<SharedLibrary> load(const std::string& path);
  /// Loads the first candidate that loads. The Error names `search.vendor`, every path tried with
  /// its origin and the loader's message, and the places that were not consulted because unset.
  static Result<SharedLibrary> load_first(const LibrarySearch& search, const haptico::DeviceConfig& config);

  bool loaded() const { return handle_ != nullptr; }
  /// The path it was loaded from ("" when nothing is loaded).
  const std::string& path() const { return path_; }
  /// Address of the exported symbol `name`, or nullptr when absent.
  void* symbol(const char* name) const;

  /// Sets `fn` to the exported function `name`; an Error naming the library and the symbol when absent.
  template <typename Fn>
  Status bind(Fn*& fn, const char* name) const {
    void* address = symbol(name);
    if (address == nullptr) return missing_symbol(name);
    fn = std::bit_cast<Fn*>(address);
    return Ok{};
  }

 private:
  SharedLibrary(void* handle, std::string path) : handle_(handle), path_(std::move(path)) {}
  Error missing_symbol(const char* name) const;
  void reset();

  void* handle_ = nullptr;
  std::string path_;
};

/// What a driver's open() does first: loads the first library of `search` (given `config`) and
/// binds the vendor's functions into a new `Api` with `bind_api`; on success `library` and `api`
/// hold them. Errors are prefixed with "`driver`: ".
template <typename Api>
Status load_vendor_api(std::string_view driver, const LibrarySearch& search,
                       const haptico::DeviceConfig& config, Status (*bind_api)(const SharedLibrary&, Api&),
                       SharedLibrary& library, std::unique_ptr<Api>& api) {
  auto loaded = SharedLibrary::load_first(search, config);
  if (!loaded) return Error{std::string(driver) + ": " + loaded.error().message};
  auto bound = std::make_unique<Api>();
  if (Status s = bind_api(*loaded, *bound); !s) return Error{std::string(driver) + ": " + s.error().message};
  library = std::move(loaded).value();
  api = std::move(bound);
  return Ok{};
}

}  // namespace uh::devices
