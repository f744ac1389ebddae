// The C API's shared parts: version, per-thread errors, status names, argument helpers, tables.

#include <algorithm>
#include <cmath>

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

uh_status null_argument(const char* function, const char* argument) {
  return fail(UH_ERROR_INVALID_ARGUMENT, fmt::format("{}: {} is NULL", function, argument));
}

uh_status stale(const char* function, const char* kind) {
  return fail(UH_ERROR_STALE_HANDLE,
              fmt::format("{}: the {} handle is not open (closed, freed, never opened, or another kind)",
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
    case UH_ERROR_FAILED:
      return "UH_ERROR_FAILED";
    case UH_ERROR_INTERNAL:
      return "UH_ERROR_INTERNAL";
    default:
      return "unknown uh_status";
  }
}

}  // extern "C"
