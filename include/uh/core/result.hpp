#pragma once
/// \file
/// Result<T>: what setup code that can fail returns (after Jolt's Result).
///
/// Setup paths (loading a mesh, opening a device, parsing a scene) return a Result whose error
/// message a user can act on: it names the file or field and says what is wrong and what was
/// expected. Real-time paths never return a Result: they count failures instead.

#include <cassert>
#include <cstdint>
#include <string>
#include <utility>
#include <variant>

namespace uh {

/// What failed, for callers that tell failures apart (the C API's statuses). Set where the failure
/// arises, or by the stage that knows what its callees do (a mesh reader's failures are the file's).
enum class ErrorKind : std::uint8_t {
  kUnspecified,  ///< not told apart; the caller decides from what it called
  kInvalid,      ///< a value the caller gave is out of range or inconsistent
  kFile,         ///< a file could not be found, read or written, or its content is wrong
  kMesh,         ///< a mesh cannot be used: open, non-manifold, degenerate, no volume, not packable
  kDevice,       ///< a haptic device: unknown driver, bad settings, would not open, faulted
  kThread,       ///< a thread could not start or ended on its own
  kBusy,         ///< in use or full: a device another tool holds, a table with no free slot
};

/// A failure with a message meant for the user, e.g.
/// "bunny.obj: mesh is not closed: 64 boundary edges (a closed 2-manifold mesh is required)".
struct Error {
  std::string message;
  ErrorKind kind = ErrorKind::kUnspecified;

  /// This error, of `kind` unless its source told a kind already (a stage marking its callees').
  Error classified(ErrorKind fallback) const& {
    return Error{message, kind == ErrorKind::kUnspecified ? fallback : kind};
  }
};

/// Either a value or an Error. Check has_value() (or operator bool) before value().
template <typename T>
class [[nodiscard]] Result {
 public:
  Result(T value) : storage_(std::in_place_index<0>, std::move(value)) {}  // NOLINT: implicit by design
  Result(Error error) : storage_(std::in_place_index<1>, std::move(error)) {}  // NOLINT: implicit by design

  bool has_value() const { return storage_.index() == 0; }
  explicit operator bool() const { return has_value(); }

  T& value() & {
    assert(has_value() && "uh::Result::value(): the result holds an error");
    return std::get<0>(storage_);
  }
  const T& value() const& {
    assert(has_value() && "uh::Result::value(): the result holds an error");
    return std::get<0>(storage_);
  }
  T&& value() && {
    assert(has_value() && "uh::Result::value(): the result holds an error");
    return std::get<0>(std::move(storage_));
  }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }

  const Error& error() const {
    assert(!has_value() && "uh::Result::error(): the result holds a value");
    return std::get<1>(storage_);
  }

 private:
  std::variant<T, Error> storage_;
};

/// Result of an operation that returns nothing on success.
struct Ok {};
using Status = Result<Ok>;

}  // namespace uh
