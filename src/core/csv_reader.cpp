#include "uh/core/csv_reader.hpp"

#include <fmt/format.h>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <utility>

namespace uh {

namespace {

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
  return s;
}

}  // namespace

void split_csv_line(std::string_view line, std::vector<std::string_view>& fields) {
  fields.clear();
  std::size_t begin = 0;
  while (true) {
    const std::size_t comma = line.find(',', begin);
    fields.push_back(
        trim(line.substr(begin, comma == std::string_view::npos ? std::string_view::npos : comma - begin)));
    if (comma == std::string_view::npos) return;
    begin = comma + 1;
  }
}

bool parse_csv_number(std::string_view field, double& out) {
  field = trim(field);
  // from_chars takes no '+'; a second sign ("+-1") stays an error
  if (!field.empty() && field.front() == '+') {
    field.remove_prefix(1);
    if (!field.empty() && (field.front() == '+' || field.front() == '-')) return false;
  }
  if (field.empty()) return false;
  double value = 0.0;
  const auto [end, ec] = std::from_chars(field.data(), field.data() + field.size(), value);
  if (ec != std::errc{} || end != field.data() + field.size() || !std::isfinite(value)) return false;
  out = value;
  return true;
}

CsvReader::CsvReader(std::istream& in, std::string source_name)
    : in_(&in), source_name_(std::move(source_name)) {}

Result<CsvReader> CsvReader::open(const std::filesystem::path& path, std::string_view what) {
  auto file = std::make_unique<std::ifstream>(path);
  if (!*file) {
    const int reason = errno;
    return Error{fmt::format("{}: cannot open the {} ({})", path.string(), what,
                             reason != 0 ? std::strerror(reason) : "unknown reason")};
  }
  CsvReader reader(*file, path.string());
  reader.owned_ = std::move(file);
  return reader;
}

bool CsvReader::read_content_line() {
  while (std::getline(*in_, line_)) {
    ++line_number_;
    const std::string_view text = trim(line_);
    if (text.empty() || text.front() == '#') continue;
    split_csv_line(line_, split_);
    field_begin_.clear();
    field_size_.clear();
    for (const std::string_view f : split_) {
      field_begin_.push_back(static_cast<std::size_t>(f.data() - line_.data()));
      field_size_.push_back(f.size());
    }
    return true;
  }
  return false;
}

Status CsvReader::read_header(std::span<const std::string_view> implied) {
  columns_.clear();
  pending_row_ = false;
  if (!read_content_line()) {
    return Error{fmt::format("{}: no header line (the file is empty or holds only comments)", source_name_)};
  }
  double first = 0.0;
  if (!implied.empty() && parse_csv_number(field(0), first)) {
    columns_.assign(implied.begin(), implied.end());
    header_line_ = 0;
    pending_row_ = true;
    return Ok{};
  }
  header_line_ = line_number_;
  for (std::size_t i = 0; i < field_begin_.size(); ++i) {
    const std::string_view name = field(i);
    for (std::size_t k = 0; k < columns_.size(); ++k) {
      if (!name.empty() && columns_[k] == name) {
        return error(
            fmt::format("the header names column '{}' twice (fields {} and {})", name, k + 1, i + 1));
      }
    }
    columns_.emplace_back(name);
  }
  return Ok{};
}

std::optional<std::size_t> CsvReader::find_column(std::string_view name) const {
  for (std::size_t k = 0; k < columns_.size(); ++k) {
    if (columns_[k] == name) return k;
  }
  return std::nullopt;
}

Result<std::size_t> CsvReader::column(std::string_view name, std::string_view expected) const {
  if (const auto k = find_column(name)) return *k;
  return Error{fmt::format("{}:{}: the header lacks column '{}' (expected columns {})", source_name_,
                           header_line_ != 0 ? header_line_ : line_number_, name, expected)};
}

Result<bool> CsvReader::next_row() {
  if (pending_row_) {
    pending_row_ = false;
  } else if (!read_content_line()) {
    return false;
  }
  if (field_begin_.size() != columns_.size()) {
    if (header_line_ == 0) {
      std::string names;
      for (const std::string& c : columns_) names += fmt::format("{}{}", names.empty() ? "" : ",", c);
      return error(
          fmt::format("found {} fields, expected {} ({})", field_begin_.size(), columns_.size(), names));
    }
    return error(fmt::format("found {} fields, expected {} as named by the header on line {}",
                             field_begin_.size(), columns_.size(), header_line_));
  }
  return true;
}

std::string_view CsvReader::field(std::size_t column) const {
  return std::string_view(line_).substr(field_begin_[column], field_size_[column]);
}

Result<double> CsvReader::number(std::size_t column) const {
  double v = 0.0;
  if (parse_csv_number(field(column), v)) return v;
  return error(fmt::format("column '{}' (field {}) is '{}', expected a finite number", columns_[column],
                           column + 1, field(column)));
}

Error CsvReader::error(std::string_view what) const {
  return Error{fmt::format("{}:{}: {}", source_name_, line_number_, what)};
}

}  // namespace uh
