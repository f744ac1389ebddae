// libFuzzer target for the in-tree mesh reader (parse_obj_or_stl, behind read_obj_or_stl: what the
// Windows build reads every mesh with) and the validation after it: any bytes must give a mesh or an error
// that starts with the file's name, never a crash, an uncaught exception or a hang. The bytes choose the
// format as its file would: a binary STL's size fits its triangle count and an ASCII STL begins with "solid"
// (both read as .stl), anything else is read as .obj. Seeds: fuzz/mesh_seeds.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>

#include "uh/collette/mesh_import.hpp"

namespace {

bool looks_like_stl(std::string_view bytes) {
  if (bytes.size() >= 84) {
    std::uint32_t count = 0;
    std::memcpy(&count, bytes.data() + 80, 4);
    if (bytes.size() == 84 + 50 * std::size_t{count}) return true;
  }
  return bytes.substr(0, 5) == "solid";
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const std::string name = looks_like_stl(bytes) ? "input.stl" : "input.obj";
  auto raw = uh::collette::parse_obj_or_stl(bytes, name);
  if (!raw) {
    if (raw.error().message.rfind(name, 0) != 0) std::abort();
    return 0;
  }
  if (raw->source_name != name) std::abort();
  auto mesh = uh::collette::validate_mesh(std::move(*raw));
  if (!mesh && mesh.error().message.rfind(name, 0) != 0) std::abort();
  if (mesh && (mesh->triangles.empty() || !(mesh->report.volume > 0.0))) std::abort();
  return 0;
}
