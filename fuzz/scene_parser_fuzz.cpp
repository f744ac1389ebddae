// libFuzzer target for the scene parser: any text must give a scene or an error that starts with
// the file name and names what is wrong, never a crash, an uncaught exception or a hang. The
// repository's scenes are the seeds (scripts/test.sh passes scenes/ as a read-only corpus).
//
// Mesh and .ist paths resolve against a folder that does not exist, so the parser never reads
// files outside the input; their errors are part of what is checked.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "uh/controllers/scene.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto scene = uh::controllers::parse_scene(text, "fuzz.json", "/nonexistent-uh-fuzz-base");
  if (!scene) {
    const std::string& message = scene.error().message;
    if (message.rfind("fuzz.json: ", 0) != 0 || message.size() <= 11) std::abort();
    return 0;
  }
  // a parsed scene is within the documented ranges
  if (scene->objects.empty() || !(scene->haptic_hz >= 1.0 && scene->haptic_hz <= 10000.0) ||
      !(scene->collision_hz >= 0.0 && scene->collision_hz <= 10000.0) || !(scene->coherence_skin >= 0.0))
    std::abort();
  return 0;
}
