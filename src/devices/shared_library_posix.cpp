// The POSIX loader (dlopen, dlsym, dlclose): the only file that uses it.
#include <dlfcn.h>

#include "platform_library.hpp"

namespace uh::devices::platform {

void* load_library(const char* path, std::string& error) {
  // RTLD_NOW: a library missing a dependency fails here, not in the middle of a haptic tick;
  // RTLD_LOCAL: its symbols do not leak into libraries loaded later (two vendors' libraries, stand-ins)
  void* handle = dlopen(path, RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) {
    const char* message = dlerror();
    error = message != nullptr ? message : "the system loader gave no reason";
  }
  return handle;
}

void* find_symbol(void* handle, const char* name) { return dlsym(handle, name); }

void unload_library(void* handle) { dlclose(handle); }

}  // namespace uh::devices::platform
