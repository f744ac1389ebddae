#include "uh/devices/shared_library.hpp"

#include <fmt/format.h>
#include <cstdlib>
#include <utility>

#include "platform_library.hpp"

namespace uh::devices {

namespace {
constexpr const char* kConfigOrigin = "tool.device.config.library";
constexpr const char* kInstallOrigin = "the vendor's install name";
}  // namespace

std::vector<LibraryCandidate> library_candidates(const LibrarySearch& search,
                                                 const haptico::DeviceConfig& config) {
  if (config.has("library")) return {{config.text("library", ""), kConfigOrigin}};
  const char* env =
      search.environment_variable.empty() ? nullptr : std::getenv(search.environment_variable.c_str());
  if (env != nullptr && *env != '\0') return {{env, search.environment_variable}};
  std::vector<LibraryCandidate> out;
  for (const std::string& name : search.install_names) out.push_back({name, kInstallOrigin});
  return out;
}

SharedLibrary::~SharedLibrary() { reset(); }

SharedLibrary::SharedLibrary(SharedLibrary&& other) noexcept
    : handle_(std::exchange(other.handle_, nullptr)), path_(std::move(other.path_)) {}

SharedLibrary& SharedLibrary::operator=(SharedLibrary&& other) noexcept {
  if (this != &other) {
    reset();
    handle_ = std::exchange(other.handle_, nullptr);
    path_ = std::move(other.path_);
  }
  return *this;
}

void SharedLibrary::reset() {
  if (handle_ != nullptr) platform::unload_library(handle_);
  handle_ = nullptr;
  path_.clear();
}

Result<SharedLibrary> SharedLibrary::load(const std::string& path) {
  std::string error;
  void* handle = platform::load_library(path.c_str(), error);
  if (handle == nullptr) return Error{error};
  return SharedLibrary(handle, path);
}

Result<SharedLibrary> SharedLibrary::load_first(const LibrarySearch& search,
                                                const haptico::DeviceConfig& config) {
  const std::vector<LibraryCandidate> candidates = library_candidates(search, config);
  std::string tried;
  for (const LibraryCandidate& c : candidates) {
    auto library = load(c.path);
    if (library) return library;
    tried += fmt::format("\n  {} (from {}): {}", c.path, c.origin, library.error().message);
  }
  // say which places were skipped, so that a user knows every way to point the driver at the library
  std::string skipped;
  if (!config.has("library")) skipped += fmt::format("\n  {} is not set", kConfigOrigin);
  if (candidates.empty() || candidates.front().origin == kInstallOrigin)
    skipped += fmt::format("\n  the environment variable {} is not set", search.environment_variable);
  return Error{fmt::format("could not load the {} library; tried:{}{}", search.vendor, tried, skipped)};
}

void* SharedLibrary::symbol(const char* name) const {
  return handle_ == nullptr ? nullptr : platform::find_symbol(handle_, name);
}

Error SharedLibrary::missing_symbol(const char* name) const {
  return Error{
      fmt::format("{} does not export {}: not the expected library or an unsupported version", path_, name)};
}

}  // namespace uh::devices
