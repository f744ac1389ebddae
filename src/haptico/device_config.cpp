#include "uh/haptico/device_config.hpp"

#include <fmt/format.h>
#include <vector>

#include "uh/core/csv_reader.hpp"

namespace uh::haptico {

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
  if (!parse_csv_number(it->second, v)) {
    return Error{fmt::format("device setting '{}': '{}' is not a finite number", key, it->second)};
  }
  return v;
}

Result<Vec3> DeviceConfig::vec3(const std::string& key, const Vec3& fallback) const {
  const auto it = values_.find(key);
  if (it == values_.end()) return fallback;
  // one CSV line of three numbers
  std::vector<std::string_view> fields;
  split_csv_line(it->second, fields);
  double c[3] = {};
  if (fields.size() != 3 || !parse_csv_number(fields[0], c[0]) || !parse_csv_number(fields[1], c[1]) ||
      !parse_csv_number(fields[2], c[2])) {
    return Error{fmt::format("device setting '{}': '{}' is not a vector \"x,y,z\" of three finite numbers", key,
                             it->second)};
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
