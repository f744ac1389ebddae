#include "uh/core/json_fields.hpp"

#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "uh/core/json_nesting.hpp"

namespace uh {

using nlohmann::json;

Result<json> parse_json_document(std::string_view text) {
  // nothing below (the parser, a dump, a destructor) recurses deeply on a file's or a client's text
  if (json_nesting_depth(text) > kMaxJsonNesting)
    return Error{fmt::format("the JSON is nested deeper than {} levels", kMaxJsonNesting)};
  try {
    return json::parse(text);
  } catch (const json::exception& e) {
    // parse_error for bad syntax, out_of_range for a number too large for a double (found by the
    // scene fuzzer): both are the text's fault
    return Error{fmt::format("not valid JSON: {}", e.what())};
  }
}

const json* JsonFields::field(const json& object, std::string_view name, std::string_view path) {
  if (!ok()) return nullptr;
  if (!object.is_object()) {
    const std::string_view where = path.empty() ? std::string_view("the message") : path;
    return fail(where.ends_with('.') ? where.substr(0, where.size() - 1) : where, "must be an object");
  }
  const auto it = object.find(name);
  if (it == object.end()) return fail(fmt::format("{}{}", path, name), "is missing");
  return &*it;
}

const json* JsonFields::optional(const json& object, std::string_view name) const {
  if (!object.is_object()) return nullptr;
  const auto it = object.find(name);
  return it == object.end() ? nullptr : &*it;
}

double JsonFields::number(const json& object, std::string_view name, std::string_view path) {
  const json* f = field(object, name, path);
  return f == nullptr ? 0.0 : number_of(*f, fmt::format("{}{}", path, name));
}

int JsonFields::integer(const json& object, std::string_view name, std::string_view path) {
  const json* f = field(object, name, path);
  return f == nullptr ? 0 : integer_of(*f, fmt::format("{}{}", path, name));
}

bool JsonFields::boolean(const json& object, std::string_view name, std::string_view path) {
  const json* f = field(object, name, path);
  if (f == nullptr) return false;
  if (!f->is_boolean()) return fail(fmt::format("{}{}", path, name), "must be true or false"), false;
  return f->get<bool>();
}

std::string JsonFields::text(const json& object, std::string_view name, std::string_view path) {
  const json* f = field(object, name, path);
  return f == nullptr ? std::string() : text_of(*f, fmt::format("{}{}", path, name));
}

const json* JsonFields::array(const json& object, std::string_view name, std::string_view path) {
  const json* f = field(object, name, path);
  if (f == nullptr) return nullptr;
  if (!f->is_array()) return fail(fmt::format("{}{}", path, name), "must be an array");
  return f;
}

double JsonFields::number_of(const json& value, std::string_view path) {
  if (!ok()) return 0.0;
  if (!value.is_number() || !std::isfinite(value.get<double>()))
    return fail(path, "must be a finite number"), 0.0;
  return value.get<double>();
}

int JsonFields::integer_of(const json& value, std::string_view path) {
  if (!ok()) return 0;
  if (!value.is_number_integer()) return fail(path, "must be an integer"), 0;
  // an unsigned value above int64's range reads as a negative int64: compare the unsigned one
  if (value.is_number_unsigned() &&
      value.get<std::uint64_t>() > static_cast<std::uint64_t>(std::numeric_limits<int>::max()))
    return fail(path, "must be an integer"), 0;
  const auto v = value.get<std::int64_t>();
  if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
    return fail(path, "must be an integer"), 0;
  return static_cast<int>(v);
}

std::string JsonFields::text_of(const json& value, std::string_view path) {
  if (!ok()) return {};
  if (!value.is_string()) return fail(path, "must be a string"), std::string();
  return value.get<std::string>();
}

const json* JsonFields::fail(std::string_view path, std::string_view what) {
  if (ok()) error_ = fmt::format("'{}' {}", path, what);
  return nullptr;
}

}  // namespace uh
