// The Windows loader (LoadLibrary, GetProcAddress, FreeLibrary): the only file that uses it.
#include <windows.h>

#include <bit>
#include <string>

#include "platform_library.hpp"

namespace uh::devices::platform {

void* load_library(const char* path, std::string& error) {
  HMODULE handle = LoadLibraryA(path);
  if (handle == nullptr) {
    const DWORD code = GetLastError();
    char text[512] = {};
    const DWORD n = FormatMessageA(FORMAT_MESSAGE_FROM_SYSTEM | FORMAT_MESSAGE_IGNORE_INSERTS, nullptr, code,
                                   0, text, sizeof(text), nullptr);
    std::string message(text, n);
    while (!message.empty() && (message.back() == '\n' || message.back() == '\r' || message.back() == ' '))
      message.pop_back();
    error = (message.empty() ? std::string("the system loader gave no reason") : message) + " (error " +
            std::to_string(code) + ")";
  }
  return handle;
}

void* find_symbol(void* handle, const char* name) {
  return std::bit_cast<void*>(GetProcAddress(static_cast<HMODULE>(handle), name));
}

void unload_library(void* handle) { FreeLibrary(static_cast<HMODULE>(handle)); }

}  // namespace uh::devices::platform
