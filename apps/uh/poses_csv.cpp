#include "poses_csv.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

namespace uh::cli {
namespace {

std::vector<std::string> split_csv_line(const std::string& line) {
  std::vector<std::string> fields;
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, ',')) {
    // trim spaces and a trailing carriage return (files written on Windows)
    const auto first = field.find_first_not_of(" \t\r");
    const auto last = field.find_last_not_of(" \t\r");
    fields.push_back(first == std::string::npos ? std::string{} : field.substr(first, last - first + 1));
  }
  if (!line.empty() && line.back() == ',') fields.emplace_back();
  return fields;
}

bool parse_double(const std::string& text, double& out) {
  const char* begin = text.data();
  const char* end = begin + text.size();
  const auto [ptr, ec] = std::from_chars(begin, end, out);
  return ec == std::errc{} && ptr == end && std::isfinite(out);
}

}  // namespace

Result<std::vector<PoseRow>> read_poses_csv(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) return Error{fmt::format("{}: cannot open the pose file", path.string())};

  static constexpr std::array<const char*, 8> kColumns = {"id", "tx", "ty", "tz", "qw", "qx", "qy", "qz"};
  std::array<int, 8> column_of{};
  column_of.fill(-1);

  std::string line;
  int line_number = 0;
  bool have_header = false;
  std::vector<PoseRow> rows;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const auto fields = split_csv_line(line);
    if (!have_header) {
      for (std::size_t c = 0; c < fields.size(); ++c)
        for (std::size_t k = 0; k < kColumns.size(); ++k)
          if (fields[c] == kColumns[k]) column_of[k] = static_cast<int>(c);
      for (std::size_t k = 0; k < kColumns.size(); ++k)
        if (column_of[k] < 0)
          return Error{fmt::format("{}:{}: header lacks column '{}' (expected id,tx,ty,tz,qw,qx,qy,qz)",
                                   path.string(), line_number, kColumns[k])};
      have_header = true;
      continue;
    }
    PoseRow row;
    std::array<double, 7> v{};
    for (std::size_t k = 0; k < kColumns.size(); ++k) {
      const auto c = static_cast<std::size_t>(column_of[k]);
      if (c >= fields.size())
        return Error{fmt::format("{}:{}: row has {} fields, column '{}' is missing", path.string(), line_number,
                                 fields.size(), kColumns[k])};
      if (k == 0) {
        row.id = fields[c];
        continue;
      }
      if (!parse_double(fields[c], v[k - 1]))
        return Error{fmt::format("{}:{}: column '{}' is '{}', expected a finite number", path.string(),
                                 line_number, kColumns[k], fields[c])};
    }
    // scaled by its largest component first, so that neither 1e200 nor 1e-200 over- or underflows
    const double largest = std::max({std::abs(v[3]), std::abs(v[4]), std::abs(v[5]), std::abs(v[6])});
    if (!(largest > 0.0))
      return Error{fmt::format("{}:{}: quaternion (qw,qx,qy,qz) is zero", path.string(), line_number)};
    const Quat q{v[3] / largest, v[4] / largest, v[5] / largest, v[6] / largest};
    row.b_in_a = Pose{normalized(q), Vec3{v[0], v[1], v[2]}};
    rows.push_back(std::move(row));
  }
  if (!have_header) return Error{fmt::format("{}: empty file, expected a header id,tx,ty,tz,qw,qx,qy,qz", path.string())};
  if (rows.empty()) return Error{fmt::format("{}: no pose rows after the header", path.string())};
  return rows;
}

}  // namespace uh::cli
