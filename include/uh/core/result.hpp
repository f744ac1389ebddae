#pragma once
/// \file
/// Result<T>: what setup code that can fail returns (after Jolt's Result).
///
/// Setup paths (loading a mesh, opening a device, parsing a scene) return a Result whose error
/// message a user can act on: it names the file or field and says what is wrong and what was
/// expected. Real-time paths never return a Result: they count failures instead.

#include <cassert>
#include <string>
#include <utility>
#include <variant>

namespace uh {

/// A failure with a message meant for the user, e.g.
/// "bunny.obj: mesh is not closed: 64 boundary edges (a closed 2-manifold mesh is required)".
struct Error {
  std::string message;
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
