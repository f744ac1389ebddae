#include "poses_csv.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include <fmt/format.h>

#include "uh/core/csv_reader.hpp"

namespace uh::cli {

Result<std::vector<PoseRow>> read_poses_csv(const std::filesystem::path& path) {
  auto opened = CsvReader::open(path, "pose file");
  if (!opened) return opened.error();
  CsvReader& csv = *opened;
  static constexpr std::string_view kExpected = "id,tx,ty,tz,qw,qx,qy,qz";
  static constexpr std::array<std::string_view, 8> kColumns = {"id", "tx", "ty", "tz",
                                                               "qw", "qx", "qy", "qz"};
  if (auto header = csv.read_header(); !header) {
    return Error{fmt::format("{}: empty file, expected a header {}", path.string(), kExpected)};
  }
  std::array<std::size_t, 8> column_of{};
  for (std::size_t k = 0; k < kColumns.size(); ++k) {
    auto c = csv.column(kColumns[k], kExpected);
    if (!c) return c.error();
    column_of[k] = *c;
  }

  std::vector<PoseRow> rows;
  while (true) {
    auto more = csv.next_row();
    if (!more) return more.error();
    if (!*more) break;
    PoseRow row;
    row.id = std::string(csv.field(column_of[0]));
    std::array<double, 7> v{};
    for (std::size_t k = 1; k < kColumns.size(); ++k) {
      auto number = csv.number(column_of[k]);
      if (!number) return number.error();
      v[k - 1] = *number;
    }
    // scaled by its largest component first, so that neither 1e200 nor 1e-200 over- or underflows
    const double largest = std::max({std::abs(v[3]), std::abs(v[4]), std::abs(v[5]), std::abs(v[6])});
    if (!(largest > 0.0)) return csv.error("quaternion (qw,qx,qy,qz) is zero");
    const Quat q{v[3] / largest, v[4] / largest, v[5] / largest, v[6] / largest};
    row.b_in_a = Pose{normalized(q), Vec3{v[0], v[1], v[2]}};
    rows.push_back(std::move(row));
  }
  if (rows.empty()) return Error{fmt::format("{}: no pose rows after the header", path.string())};
  return rows;
}

}  // namespace uh::cli
