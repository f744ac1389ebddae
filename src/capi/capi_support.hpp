#pragma once
// What every C API source shares: the per-thread error, the exception barrier, argument checks,
// and the handle tables of trees, scenes and sessions.

#include <cstdint>
#include <cstring>
#include <memory>
#include <new>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "handle_table.hpp"
#include "uh/collette/ist_file.hpp"
#include "uh/collette/sphere_tree.hpp"
#include "uh/controllers/scene.hpp"
#include "uh/core/math.hpp"
#include "uh/core/result.hpp"
#include "uh/uh.h"

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

/// UH_ERROR_INVALID_ARGUMENT naming the function and the argument that is NULL.
uh_status null_argument(const char* function, const char* argument);

/// Checks a crossing struct: not NULL and struct_size at least this version's size.
template <typename Struct>
uh_status check_struct(const char* function, const char* argument, const Struct* value) {
  if (value == nullptr) return null_argument(function, argument);
  if (value->struct_size < sizeof(Struct))
    return fail(UH_ERROR_INVALID_ARGUMENT,
                fmt::format("{}: {}->struct_size is {}, expected at least {} (set it to sizeof the struct)",
                            function, argument, value->struct_size, sizeof(Struct)));
  return UH_OK;
}

/// A pose from C arrays (position [m], orientation w, x, y, z); the orientation must be a finite,
/// non-zero quaternion (it is normalised) and the position finite.
Result<Pose> pose_from_arrays(const double position[3], const double orientation[4]);

/// An immutable tree with what its .ist said about it (lengths in metres).
struct TreeBox {
  std::shared_ptr<const collette::SphereTree> tree;
  collette::IstMetadata meta;
};

struct SceneBox {
  controllers::Scene scene;
};

struct SessionBox;  // capi_session.cpp

HandleTable<TreeBox>& tree_table();
HandleTable<SceneBox>& scene_table();

template <typename Handle>
std::uintptr_t handle_value(const Handle* handle) {
  return reinterpret_cast<std::uintptr_t>(handle);
}
template <typename Handle>
Handle* as_handle(std::uintptr_t value) {
  return reinterpret_cast<Handle*>(value);
}

/// UH_ERROR_STALE_HANDLE naming the function and the kind of handle.
uh_status stale(const char* function, const char* kind);

/// Copies a C string, or "" for NULL.
inline std::string text_or_empty(const char* text) {
  return text != nullptr ? std::string(text) : std::string();
}

}  // namespace uh::capi
