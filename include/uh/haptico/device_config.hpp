#pragma once
/// \file
/// DeviceConfig: the settings a driver is created with (name -> value text).

#include <initializer_list>
#include <map>
#include <string>
#include <string_view>

#include "uh/core/math.hpp"
#include "uh/core/result.hpp"

namespace uh::haptico {

/// Driver settings as key -> text, e.g. {"start": "0,0,0", "duration_s": "2"}, as read from a
/// scene file or the command line. Typed getters parse on demand and return an Error naming the
/// key and the expected form. Setup only (not real-time safe).
class DeviceConfig {
 public:
  DeviceConfig() = default;
  DeviceConfig(std::initializer_list<std::pair<const std::string, std::string>> values) : values_(values) {}

  DeviceConfig& set(const std::string& key, std::string value);
  DeviceConfig& set(const std::string& key, double value);
  DeviceConfig& set(const std::string& key, const Vec3& value);

  bool has(const std::string& key) const { return values_.count(key) != 0; }
  /// The text of `key`, or `fallback` when absent.
  std::string text(const std::string& key, const std::string& fallback) const;
  /// A finite number; `fallback` when absent; an Error when present but not a number.
  Result<double> number(const std::string& key, double fallback) const;
  /// A vector written "x,y,z"; `fallback` when absent.
  Result<Vec3> vec3(const std::string& key, const Vec3& fallback) const;
  /// Rejects keys not in `known` (catches typos such as "raduis"); `driver` names the driver in the message.
  Status check_keys(std::initializer_list<std::string_view> known, std::string_view driver) const;

  const std::map<std::string, std::string>& values() const { return values_; }

 private:
  std::map<std::string, std::string> values_;
};

}  // namespace uh::haptico
