#include "uh/haptico/device_config.hpp"

#include <charconv>
#include <cmath>
#include <fmt/format.h>

namespace uh::haptico {

namespace {

bool parse_double(std::string_view s, double& out) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  if (s.empty()) return false;
  if (s.front() == '+') s.remove_prefix(1);
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
  return ec == std::errc{} && end == s.data() + s.size() && std::isfinite(out);
}

}  // namespace

DeviceConfig& DeviceConfig::set(const std::string& key, std::string value) {
  values_[key] = std::move(value);
  return *this;
}

DeviceConfig& DeviceConfig::set(const std::string& key, double value) {
  values_[key] = fmt::format("{}", value);
  return *this;
}

DeviceConfig& DeviceConfig::set(const std::string& key, const Vec3& value) {
  values_[key] = fmt::format("{},{},{}", value.x, value.y, value.z);
  return *this;
}

std::string DeviceConfig::text(const std::string& key, const std::string& fallback) const {
  const auto it = values_.find(key);
  return it == values_.end() ? fallback : it->second;
}

Result<double> DeviceConfig::number(const std::string& key, double fallback) const {
  const auto it = values_.find(key);
  if (it == values_.end()) return fallback;
  double v = 0.0;
  if (!parse_double(it->second, v)) {
    return Error{fmt::format("device setting '{}': '{}' is not a finite number", key, it->second)};
  }
  return v;
}

Result<Vec3> DeviceConfig::vec3(const std::string& key, const Vec3& fallback) const {
  const auto it = values_.find(key);
  if (it == values_.end()) return fallback;
  const std::string_view s = it->second;
  double c[3] = {};
  std::size_t begin = 0;
  for (int i = 0; i < 3; ++i) {
    const std::size_t comma = s.find(',', begin);
    const bool last = i == 2;
    if (last != (comma == std::string_view::npos) ||
        !parse_double(s.substr(begin, last ? std::string_view::npos : comma - begin), c[i])) {
      return Error{fmt::format("device setting '{}': '{}' is not a vector \"x,y,z\" of three finite numbers", key, s)};
    }
    begin = comma + 1;
  }
  return Vec3{c[0], c[1], c[2]};
}

Status DeviceConfig::check_keys(std::initializer_list<std::string_view> known, std::string_view driver) const {
  for (const auto& [key, value] : values_) {
    bool found = false;
    for (std::string_view k : known) found = found || k == key;
    if (!found) {
      std::string list;
      for (std::string_view k : known) list += fmt::format("{}{}", list.empty() ? "" : ", ", k);
      return Error{fmt::format("{}: unknown setting '{}' (known settings: {})", driver, key, list)};
    }
  }
  return Ok{};
}

}  // namespace uh::haptico
