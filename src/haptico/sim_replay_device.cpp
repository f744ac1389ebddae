#include "uh/haptico/sim_replay_device.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fmt/format.h>
#include <fstream>
#include <string_view>
#include <utility>

namespace uh::haptico {

namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

bool to_number(std::string_view s, double& out) {
  s = trim(s);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  if (s.empty()) return false;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
  return ec == std::errc{} && end == s.data() + s.size();
}

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t begin = 0;
  while (true) {
    const std::size_t comma = line.find(',', begin);
    fields.push_back(line.substr(begin, comma == std::string_view::npos ? std::string_view::npos : comma - begin));
    if (comma == std::string_view::npos) break;
    begin = comma + 1;
  }
  return fields;
}

constexpr const char* kColumns = "time_s,x,y,z,qw,qx,qy,qz";

}  // namespace

Result<std::vector<TrajectorySample>> SimReplayDevice::parse_csv(std::istream& in, const std::string& source_name) {
  std::vector<TrajectorySample> samples;
  std::string line;
  int line_number = 0;
  bool seen_content = false;
  // where each of time_s,x,y,z,qw,qx,qy,qz stands in a row; a header may name them in any order
  // among other columns (a `uh run --trace` CSV: its device_time_s is the time column)
  std::size_t column[8] = {0, 1, 2, 3, 4, 5, 6, 7};
  std::size_t row_fields = 8;
  while (std::getline(in, line)) {
    ++line_number;
    const std::string_view text = trim(line);
    if (text.empty() || text.front() == '#') continue;
    const std::vector<std::string_view> fields = split(text);
    double first = 0.0;
    if (!seen_content && !to_number(fields.front(), first)) {
      // a header line: accept it only if it names the expected columns
      seen_content = true;
      static constexpr std::string_view kNames[8] = {"time_s", "x", "y", "z", "qw", "qx", "qy", "qz"};
      bool found[8] = {};
      for (std::size_t i = 0; i < fields.size(); ++i) {
        const std::string_view name = trim(fields[i]);
        for (std::size_t k = 0; k < 8; ++k) {
          const bool match = name == kNames[k] || (k == 0 && name == "device_time_s" && !found[0]);
          if (match && !found[k]) {
            column[k] = i;
            found[k] = true;
            break;
          }
        }
      }
      if (!std::all_of(std::begin(found), std::end(found), [](bool f) { return f; })) {
        return Error{fmt::format("{}:{}: header '{}' does not match the expected columns '{}'", source_name,
                                 line_number, text, kColumns)};
      }
      row_fields = fields.size();
      continue;
    }
    seen_content = true;
    if (fields.size() != row_fields) {
      return Error{fmt::format("{}:{}: expected {} comma-separated numbers ({}), found {} fields", source_name,
                               line_number, row_fields, row_fields == 8 ? kColumns : "as named by the header",
                               fields.size())};
    }
    double v[8] = {};
    for (std::size_t i = 0; i < 8; ++i) {
      if (!to_number(fields[column[i]], v[i]) || !std::isfinite(v[i])) {
        return Error{fmt::format("{}:{}: field {} ('{}') is not a finite number", source_name, line_number,
                                 column[i] + 1, trim(fields[column[i]]))};
      }
    }
    const double qn = std::sqrt(v[4] * v[4] + v[5] * v[5] + v[6] * v[6] + v[7] * v[7]);
    if (!(qn >= 1e-6) || !std::isfinite(qn)) {
      return Error{fmt::format("{}:{}: quaternion (qw,qx,qy,qz) must have a finite, non-zero length", source_name,
                               line_number)};
    }
    if (!samples.empty() && !(v[0] > samples.back().time_s)) {
      return Error{fmt::format("{}:{}: time {} s is not after the previous sample's {} s (times must increase)",
                               source_name, line_number, v[0], samples.back().time_s)};
    }
    samples.push_back({v[0], Pose{Quat{v[4] / qn, v[5] / qn, v[6] / qn, v[7] / qn}, Vec3{v[1], v[2], v[3]}}});
  }
  if (samples.empty()) {
    return Error{fmt::format("{}: no samples (expected lines of '{}')", source_name, kColumns)};
  }
  return samples;
}

Result<std::vector<TrajectorySample>> SimReplayDevice::load_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) return Error{fmt::format("{}: cannot open the trajectory file", path)};
  return parse_csv(in, path);
}

SimReplayDevice::SimReplayDevice(std::vector<TrajectorySample> samples, const SimReplayOptions& options)
    : ScriptedDevice("sim-replay", options.device), samples_(std::move(samples)), options_(options) {}

Pose SimReplayDevice::pose_at(double t) const {
  const double duration = duration_s();
  if (options_.loop && duration > 0.0) t = std::fmod(t, duration);
  const double when = samples_.front().time_s + t;
  if (when <= samples_.front().time_s) return samples_.front().pose;
  if (when >= samples_.back().time_s) return samples_.back().pose;
  const auto it = std::upper_bound(samples_.begin(), samples_.end(), when,
                                   [](double value, const TrajectorySample& s) { return value < s.time_s; });
  const TrajectorySample& b = *it;
  const TrajectorySample& a = *(it - 1);
  const double u = (when - a.time_s) / (b.time_s - a.time_s);
  Quat qb = b.pose.rotation;
  const Quat& qa = a.pose.rotation;
  if (qa.w * qb.w + qa.x * qb.x + qa.y * qb.y + qa.z * qb.z < 0.0) qb = {-qb.w, -qb.x, -qb.y, -qb.z};
  const Quat q = normalized(Quat{qa.w + u * (qb.w - qa.w), qa.x + u * (qb.x - qa.x), qa.y + u * (qb.y - qa.y),
                                 qa.z + u * (qb.z - qa.z)});
  return Pose{q, a.pose.position + u * (b.pose.position - a.pose.position)};
}

}  // namespace uh::haptico
