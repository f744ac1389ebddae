#pragma once
/// \file
/// The project's one reader of JSON fields: a document is parsed only after the nesting guard
/// (json_nesting.hpp), and fields are read by path, every error naming the field ("'level.rooms[2].min'
/// must be [x, y], two finite numbers"). Never throws, whatever the input.

#include <cstdint>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "uh/core/result.hpp"

namespace uh {

/// Parses one JSON document, the first step of every parser (scene files, the service's and the
/// game's messages): "the JSON is nested deeper than 32 levels" (checked before parsing) or
/// "not valid JSON: <the parser's message>". Never throws.
Result<nlohmann::json> parse_json_document(std::string_view text);

/// Reads the fields of parsed JSON and keeps the first thing wrong; once something is wrong, later
/// reads do nothing and return defaults, so a parser reads every field and checks ok() once.
/// A path names where the object sits ("" at the top, "level." inside `level`).
class JsonFields {
 public:
  using json = nlohmann::json;

  /// The field `name` of `object`; an error when `object` is no object or the field is absent.
  const json* field(const json& object, std::string_view name, std::string_view path = {});
  /// The field when present, else null (no error).
  const json* optional(const json& object, std::string_view name) const;

  double number(const json& object, std::string_view name, std::string_view path = {});
  int integer(const json& object, std::string_view name, std::string_view path = {});
  bool boolean(const json& object, std::string_view name, std::string_view path = {});
  std::string text(const json& object, std::string_view name, std::string_view path = {});
  /// The field as an array (its elements are read by the caller), or null.
  const json* array(const json& object, std::string_view name, std::string_view path = {});

  /// The value itself (an array element): a finite number, an int, a string.
  double number_of(const json& value, std::string_view path);
  int integer_of(const json& value, std::string_view path);
  std::string text_of(const json& value, std::string_view path);

  /// Records "'path' what" unless something was recorded already; returns null for chaining.
  const json* fail(std::string_view path, std::string_view what);

  bool ok() const { return error_.empty(); }
  /// The first thing wrong (empty: nothing).
  const std::string& error() const { return error_; }

 private:
  std::string error_;
};

}  // namespace uh
