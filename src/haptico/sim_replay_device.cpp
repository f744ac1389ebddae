#include "uh/haptico/sim_replay_device.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <string_view>
#include <utility>

#include "uh/core/csv_reader.hpp"

namespace uh::haptico {

namespace {

constexpr std::string_view kColumns = "time_s,x,y,z,qw,qx,qy,qz";
constexpr std::string_view kNames[8] = {"time_s", "x", "y", "z", "qw", "qx", "qy", "qz"};

Result<std::vector<TrajectorySample>> read_trajectory(CsvReader& csv) {
  // a file without a header holds the eight columns in order
  if (auto header = csv.read_header(kNames); !header) {
    return Error{fmt::format("{}: no samples (expected lines of '{}')", csv.source_name(), kColumns)};
  }
  // a `uh run --trace` file names its time column device_time_s
  std::size_t column[8] = {};
  for (std::size_t k = 0; k < 8; ++k) {
    const auto found = k == 0 && !csv.find_column("time_s") ? csv.find_column("device_time_s") : csv.find_column(kNames[k]);
    if (!found) return csv.column(kNames[k], kColumns).error();
    column[k] = *found;
  }
  // optional: a `uh run --trace` file carries the buttons the device reported
  const auto buttons_column = csv.find_column("buttons");
  std::vector<TrajectorySample> samples;
  while (true) {
    auto row = csv.next_row();
    if (!row) return row.error();
    if (!*row) break;
    double v[8] = {};
    for (std::size_t k = 0; k < 8; ++k) {
      auto number = csv.number(column[k]);
      if (!number) return number.error();
      v[k] = *number;
    }
    const double qn = std::sqrt(v[4] * v[4] + v[5] * v[5] + v[6] * v[6] + v[7] * v[7]);
    if (!(qn >= 1e-6) || !std::isfinite(qn)) {
      return csv.error("quaternion (qw,qx,qy,qz) must have a finite, non-zero length");
    }
    if (!samples.empty() && !(v[0] > samples.back().time_s)) {
      return csv.error(fmt::format("time {} s is not after the previous sample's {} s (times must increase)", v[0],
                                   samples.back().time_s));
    }
    std::uint32_t buttons = 0;
    if (buttons_column) {
      auto mask = csv.number(*buttons_column);
      if (!mask) return mask.error();
      if (!(*mask >= 0.0 && *mask <= 4294967295.0 && std::floor(*mask) == *mask)) {
        return csv.error(
            fmt::format("buttons {} is not a bit mask (a whole number from 0 to 4294967295)", *mask));
      }
      buttons = static_cast<std::uint32_t>(*mask);
    }
    samples.push_back(
        {v[0], Pose{Quat{v[4] / qn, v[5] / qn, v[6] / qn, v[7] / qn}, Vec3{v[1], v[2], v[3]}}, buttons});
  }
  if (samples.empty()) {
    return Error{fmt::format("{}: no samples (expected lines of '{}')", csv.source_name(), kColumns)};
  }
  return samples;
}

}  // namespace

Result<std::vector<TrajectorySample>> SimReplayDevice::parse_csv(std::istream& in, const std::string& source_name) {
  CsvReader csv(in, source_name);
  return read_trajectory(csv);
}

Result<std::vector<TrajectorySample>> SimReplayDevice::load_csv(const std::string& path) {
  auto csv = CsvReader::open(path, "trajectory file");
  if (!csv) return csv.error();
  return read_trajectory(*csv);
}

SimReplayDevice::SimReplayDevice(std::vector<TrajectorySample> samples, const SimReplayOptions& options)
    : ScriptedDevice("sim-replay", options.device), samples_(std::move(samples)), options_(options) {}

double SimReplayDevice::recording_time(double t) const {
  const double duration = duration_s();
  if (options_.loop && duration > 0.0) t = std::fmod(t, duration);
  return samples_.front().time_s + t;
}

std::uint32_t SimReplayDevice::buttons_at(double t) const {
  const double when = recording_time(t);
  // held from a sample until the next one (a press is an event, not a quantity to interpolate)
  const auto it = std::upper_bound(samples_.begin(), samples_.end(), when,
                                   [](double value, const TrajectorySample& s) { return value < s.time_s; });
  return it == samples_.begin() ? samples_.front().buttons : (it - 1)->buttons;
}

Pose SimReplayDevice::pose_at(double t) const {
  const double when = recording_time(t);
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
