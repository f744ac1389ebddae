#pragma once
// The three calls SharedLibrary needs from the system loader. One implementation per platform:
// shared_library_posix.cpp (dlopen); a Windows build adds its LoadLibrary counterpart.

#include <string>

namespace uh::devices::platform {

/// Loads `path`; nullptr with the loader's message in `error` when it fails.
void* load_library(const char* path, std::string& error);
/// The address of `name` in `handle`, or nullptr.
void* find_symbol(void* handle, const char* name);
void unload_library(void* handle);

}  // namespace uh::devices::platform
