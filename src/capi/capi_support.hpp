#pragma once
// What every C API source shares: the per-thread error, the exception barrier, argument checks,
// and the handle tables of trees, scenes and sessions.

#include <cstdint>
#include <cstring>
#include <memory>
#include <new>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "handle_table.hpp"
#include "uh/collette/ist_file.hpp"
#include "uh/collette/mesh_inside.hpp"
#include "uh/collette/sphere_tree.hpp"
#include "uh/controllers/scene.hpp"
#include "uh/core/math.hpp"
#include "uh/core/result.hpp"
#include "uh/uh.h"
#include "uh_v2_0_structs.h"

namespace uh::capi {

/// Records `message` as the calling thread's last error and returns `status`.
uh_status fail(uh_status status, std::string message);

/// Runs `body` (returning uh_status) so that no exception leaves the library: std::bad_alloc and
/// every other exception become UH_ERROR_INTERNAL with a message naming `function`.
template <typename Body>
uh_status guarded(const char* function, Body&& body) noexcept {
  try {
    return std::forward<Body>(body)();
  } catch (const std::bad_alloc&) {
    return fail(UH_ERROR_INTERNAL, fmt::format("{}: out of memory", function));
  } catch (const std::exception& e) {
    return fail(UH_ERROR_INTERNAL, fmt::format("{}: unexpected failure: {}", function, e.what()));
  } catch (...) {
    return fail(UH_ERROR_INTERNAL, fmt::format("{}: unexpected failure", function));
  }
}

/// Records `error`'s message and returns the status of its kind (ErrorKind), or `fallback` when its
/// source did not tell one (the caller knows what it called: a scene file's errors are the file's).
uh_status fail(const Error& error, uh_status fallback);

/// The ErrorKind of a status (the reverse of fail(const Error&, ...)), for an error passed on
/// from a C API call the library makes itself.
ErrorKind error_kind(uh_status status);

/// UH_ERROR_INVALID_ARGUMENT naming the function and the argument that is NULL.
uh_status null_argument(const char* function, const char* argument);

/// The sizes of every layout a struct has had in this API version, oldest first: its first
/// layout from the frozen snapshot (uh_v2_0_structs.h) and this version's. Structs grow only at
/// their end, so each older layout is a prefix of the newer ones.
template <typename Struct>
struct Layouts;
#define UH_CAPI_LAYOUTS(name)                                                            \
  template <>                                                                            \
  struct Layouts<uh_##name> {                                                            \
    static constexpr const char* kName = "uh_" #name;                                    \
    static constexpr std::size_t kSizes[] = {sizeof(uh_v2_0_##name), sizeof(uh_##name)}; \
  };
UH_CAPI_LAYOUTS(tree_build_def)
UH_CAPI_LAYOUTS(shape_def)
UH_CAPI_LAYOUTS(object_def)
UH_CAPI_LAYOUTS(tool_def)
UH_CAPI_LAYOUTS(session_def)
UH_CAPI_LAYOUTS(state)
UH_CAPI_LAYOUTS(contact_event)
UH_CAPI_LAYOUTS(tree_info)
UH_CAPI_LAYOUTS(query_result)
#undef UH_CAPI_LAYOUTS

/// Empty when `size` is the size of a layout of Struct this library knows; otherwise what is wrong,
/// naming `what` (the function and argument) and what the size should be.
template <typename Struct>
std::string size_problem(std::string_view what, std::uint32_t size) {
  for (const std::size_t known : Layouts<Struct>::kSizes)
    if (size == known) return {};
  constexpr std::size_t newest = sizeof(Struct);
  if (size > newest)
    return fmt::format(
        "{}->struct_size is {}, larger than the largest {} this library knows ({}): the program "
        "was built against a newer uh.h than this library",
        what, size, Layouts<Struct>::kName, newest);
  return fmt::format(
      "{}->struct_size is {}, which is no layout of {} (set it to sizeof the struct; this "
      "library knows {})",
      what, size, Layouts<Struct>::kName, fmt::join(Layouts<Struct>::kSizes, ", "));
}

/// UH_OK when `size` is a layout of Struct this library knows; else UH_ERROR_INVALID_ARGUMENT.
template <typename Struct>
uh_status check_size(const char* function, const char* argument, std::uint32_t size) {
  std::string why = size_problem<Struct>(fmt::format("{}: {}", function, argument), size);
  return why.empty() ? UH_OK : fail(UH_ERROR_INVALID_ARGUMENT, std::move(why));
}

/// Reads a caller's struct into `out`, which holds the defaults: the fields the caller's layout
/// has (its struct_size) are the caller's, the rest stay the defaults.
template <typename Struct>
uh_status read_def(const char* function, const char* argument, const Struct* in, Struct& out) {
  if (in == nullptr) return null_argument(function, argument);
  const std::uint32_t size = in->struct_size;
  if (auto s = check_size<Struct>(function, argument, size); s != UH_OK) return s;
  std::memcpy(static_cast<void*>(&out), static_cast<const void*>(in), size);
  out.struct_size = sizeof(Struct);
  return UH_OK;
}

/// Checks a struct the library fills: not NULL and a layout this library knows.
template <typename Struct>
uh_status check_out(const char* function, const char* argument, const Struct* out) {
  if (out == nullptr) return null_argument(function, argument);
  return check_size<Struct>(function, argument, out->struct_size);
}

/// Writes `full` into the caller's struct up to its struct_size (checked by check_out): an older
/// layout gets the fields it has, and nothing past its end.
template <typename Struct>
void write_out(const Struct& full, Struct* out) {
  const std::uint32_t size = out->struct_size;
  std::memcpy(static_cast<void*>(out), static_cast<const void*>(&full), size);
  out->struct_size = size;
}

/// uh_X_init: `defaults()` into the caller's struct, up to its struct_size.
template <typename Struct>
uh_status init_def(const char* function, Struct* def, Struct (*defaults)()) noexcept {
  return guarded(function, [&]() -> uh_status {
    if (auto s = check_out(function, "def", def); s != UH_OK) return s;
    write_out(defaults(), def);
    return UH_OK;
  });
}

/// uh_X_is_valid: 1 for a live id of `table`, else 0 (a generation check; never throws).
template <typename T>
int32_t is_live(const HandleTable<T>& table, std::uint64_t id) noexcept {
  try {
    return table.find(id) != nullptr ? 1 : 0;
  } catch (...) {
    return 0;  // the lookup could not lock: report no live object rather than guess
  }
}

/// A pose from C arrays (position [m], orientation w, x, y, z); the orientation must be a finite,
/// non-zero quaternion (it is normalised) and the position finite.
Result<Pose> pose_from_arrays(const double position[3], const double orientation[4]);

/// An immutable tree with what its .ist said about it and the surface it was packed in, if any
/// (lengths in metres).
struct TreeBox {
  std::shared_ptr<const collette::SphereTree> tree;
  collette::IstMetadata meta;
  std::optional<collette::TriangleMesh> surface;          ///< written back by uh_tree_save
  std::shared_ptr<const collette::MeshInside> surface_bvh;  ///< what a session's proxy rests on
};

struct SceneBox {
  controllers::Scene scene;
};

struct SessionBox;  // capi_session.cpp

HandleTable<TreeBox>& tree_table();
HandleTable<SceneBox>& scene_table();

/// UH_ERROR_BUSY: `kind`'s table has no free slot.
uh_status table_full(const char* kind);

/// UH_ERROR_STALE_HANDLE naming the function and the kind of handle.
uh_status stale(const char* function, const char* kind);

/// Copies a C string, or "" for NULL.
inline std::string text_or_empty(const char* text) {
  return text != nullptr ? std::string(text) : std::string();
}

}  // namespace uh::capi
