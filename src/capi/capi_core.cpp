// The C API's shared parts: version, per-thread errors, status names, argument helpers, tables.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>

#include "capi_support.hpp"

namespace uh::capi {
namespace {

thread_local std::string last_error_message;

}  // namespace

uh_status fail(uh_status status, std::string message) {
  try {
    last_error_message = std::move(message);
  } catch (...) {
    // the message could not be kept (out of memory); the status still tells what happened
  }
  return status;
}

// each kind of failure the modules tell apart, and its status
constexpr std::pair<ErrorKind, uh_status> kKindStatus[] = {{ErrorKind::kInvalid, UH_ERROR_INVALID_ARGUMENT},
                                                           {ErrorKind::kFile, UH_ERROR_FILE},
                                                           {ErrorKind::kMesh, UH_ERROR_MESH},
                                                           {ErrorKind::kDevice, UH_ERROR_DEVICE},
                                                           {ErrorKind::kThread, UH_ERROR_THREAD},
                                                           {ErrorKind::kBusy, UH_ERROR_BUSY}};

uh_status fail(const Error& error, uh_status fallback) {
  for (const auto& [kind, status] : kKindStatus)
    if (kind == error.kind) return fail(status, error.message);
  return fail(fallback, error.message);
}

ErrorKind error_kind(uh_status status) {
  for (const auto& [kind, known] : kKindStatus)
    if (known == status) return kind;
  return ErrorKind::kUnspecified;
}

uh_status table_full(const char* kind) {
  return fail(UH_ERROR_BUSY,
              fmt::format("too many {} are open at once (about a million); destroy some", kind));
}

uh_status null_argument(const char* function, const char* argument) {
  return fail(UH_ERROR_INVALID_ARGUMENT, fmt::format("{}: {} is NULL", function, argument));
}

uh_status stale(const char* function, const char* kind) {
  return fail(UH_ERROR_STALE_HANDLE,
              fmt::format("{}: the {} id is not valid (destroyed, never made, or an id of another kind)",
                          function, kind));
}

Result<Pose> pose_from_arrays(const double position[3], const double orientation[4]) {
  if (position == nullptr || orientation == nullptr)
    return Error{"position and orientation must not be NULL"};
  const Vec3 p{position[0], position[1], position[2]};
  if (!is_finite(p)) return Error{fmt::format("position ({}, {}, {}) is not finite", p.x, p.y, p.z)};
  const Quat q{orientation[0], orientation[1], orientation[2], orientation[3]};
  // scale first so that tiny and huge quaternions neither underflow nor overflow
  const double largest = std::max({std::abs(q.w), std::abs(q.x), std::abs(q.y), std::abs(q.z)});
  if (!std::isfinite(largest) || largest == 0.0)
    return Error{
        fmt::format("orientation ({}, {}, {}, {}) is not a finite non-zero quaternion", q.w, q.x, q.y, q.z)};
  const Quat scaled{q.w / largest, q.x / largest, q.y / largest, q.z / largest};
  const double n =
      std::sqrt(scaled.w * scaled.w + scaled.x * scaled.x + scaled.y * scaled.y + scaled.z * scaled.z);
  return Pose{Quat{scaled.w / n, scaled.x / n, scaled.y / n, scaled.z / n}, p};
}

// each kind's layout is a prefix of its newest: a struct grows only at its end, so that an older
// program's smaller struct is read up to its size (an input struct's new field starts past the
// older struct's end: its padding was never the caller's to set)
static_assert(offsetof(uh_tool_def, tool_offset) >= sizeof(uh_v2_0_tool_def));
static_assert(offsetof(uh_contact_event, tool) >= offsetof(uh_v2_0_contact_event, pairs) + sizeof(int32_t));
static_assert(offsetof(uh_session_def, proxy) >= sizeof(uh_v2_0_session_def));
static_assert(offsetof(uh_state, handle_position) >= sizeof(uh_v2_0_state));
static_assert(sizeof(uh_tree_build_def) == sizeof(uh_v2_0_tree_build_def) &&
                  sizeof(uh_shape_def) == sizeof(uh_v2_0_shape_def) &&
                  sizeof(uh_object_def) == sizeof(uh_v2_0_object_def) &&
                  sizeof(uh_tree_info) == sizeof(uh_v2_0_tree_info) &&
                  sizeof(uh_query_result) == sizeof(uh_v2_0_query_result),
              "a struct grew: keep its older layout in uh_v2_0_structs.h and add the new fields at its end");

HandleTable<TreeBox>& tree_table() {
  static HandleTable<TreeBox> table(1);
  return table;
}

HandleTable<SceneBox>& scene_table() {
  static HandleTable<SceneBox> table(2);
  return table;
}

}  // namespace uh::capi

using namespace uh::capi;

extern "C" {

const char* uh_version_string(void) { return UH_VERSION_STRING; }

int32_t uh_api_version(void) { return UH_API_VERSION; }

const char* uh_last_error(void) { return last_error_message.c_str(); }

const char* uh_status_name(uh_status status) {
  switch (status) {
    case UH_OK:
      return "UH_OK";
    case UH_ERROR_INVALID_ARGUMENT:
      return "UH_ERROR_INVALID_ARGUMENT";
    case UH_ERROR_STALE_HANDLE:
      return "UH_ERROR_STALE_HANDLE";
    case UH_ERROR_WRONG_STATE:
      return "UH_ERROR_WRONG_STATE";
    case UH_ERROR_VERSION:
      return "UH_ERROR_VERSION";
    case UH_ERROR_INTERNAL:
      return "UH_ERROR_INTERNAL";
    case UH_ERROR_FILE:
      return "UH_ERROR_FILE";
    case UH_ERROR_MESH:
      return "UH_ERROR_MESH";
    case UH_ERROR_DEVICE:
      return "UH_ERROR_DEVICE";
    case UH_ERROR_THREAD:
      return "UH_ERROR_THREAD";
    case UH_ERROR_BUSY:
      return "UH_ERROR_BUSY";
    default:
      return "unknown uh_status";
  }
}

}  // extern "C"
