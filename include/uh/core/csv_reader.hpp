#pragma once
/// \file
/// CsvReader: the one reader of the project's CSV inputs (replayed trajectories and session traces,
/// `uh query` pose lists, the "x,y,z" values of device settings).
///
/// The dialect: fields separated by commas, no quoting (a field never holds a comma), spaces, tabs
/// and a trailing carriage return around a field ignored; blank lines and lines whose first
/// non-blank character is '#' skipped; the first remaining line is a header naming the columns
/// (optionally implied, see read_header). Columns are found by name, in any order, among others.
/// Every error starts with "FILE:LINE: " and names the column and what is wrong. Setup only (not
/// real-time safe).

#include <cstddef>
#include <filesystem>
#include <istream>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "uh/core/result.hpp"

namespace uh {

/// Splits one line at commas into `fields` (cleared first), each trimmed of spaces, tabs and
/// carriage returns. "a,,b," gives four fields, the second and last empty. The views point into `line`.
void split_csv_line(std::string_view line, std::vector<std::string_view>& fields);

/// Parses one field as a finite number (decimal or exponent notation, an optional leading '+',
/// surrounding blanks ignored). False for anything else, including "nan", "inf" and overflow.
bool parse_csv_number(std::string_view field, double& out);

/// Reads a CSV stream row by row, with the header's column names and the line numbers kept for
/// error messages. Rows are read one at a time into a reused buffer, so a long session trace
/// needs no more memory than its longest line.
class CsvReader {
 public:
  /// Reads from `in`, which must outlive the reader; `source_name` (usually the path) starts
  /// every error message.
  CsvReader(std::istream& in, std::string source_name);
  /// Opens `path`; the error names it and `what` ("pose file": "P: cannot open the pose file (No
  /// such file or directory)").
  static Result<CsvReader> open(const std::filesystem::path& path, std::string_view what);

  /// Reads the header: the first line that is neither blank nor a comment. When `implied` column
  /// names are given and that line's first field is a number, the file has no header: the
  /// columns are `implied` and the line is the first row. Errors: no such line (an empty file);
  /// a column named twice.
  Status read_header(std::span<const std::string_view> implied = {});

  /// The index of the column called `name`, if the header has one.
  std::optional<std::size_t> find_column(std::string_view name) const;
  /// The index of the column called `name`; else an error naming the header's line and
  /// `expected` (e.g. "id,tx,ty,tz,qw,qx,qy,qz").
  Result<std::size_t> column(std::string_view name, std::string_view expected) const;

  /// Moves to the next row; false at the end of the input. Error: a row with a different number
  /// of fields than the header.
  Result<bool> next_row();
  /// The current row's field in `column` (trimmed). `column` < columns().size().
  std::string_view field(std::size_t column) const;
  /// The current row's field in `column` as a finite number; else an error naming the line,
  /// the column and the text found.
  Result<double> number(std::size_t column) const;
  /// An error about the current row: "FILE:LINE: " + `what`.
  Error error(std::string_view what) const;

  /// The header's column names (or the implied ones).
  const std::vector<std::string>& columns() const { return columns_; }
  /// The line of the current row (1-based; the header's line before the first next_row()).
  int line_number() const { return line_number_; }
  const std::string& source_name() const { return source_name_; }

 private:
  // the next line that is neither blank nor a comment, split into its fields; false at the end
  bool read_content_line();

  std::unique_ptr<std::istream> owned_;  // the file, when open() made the reader
  std::istream* in_ = nullptr;
  std::string source_name_;
  std::string line_;
  std::vector<std::string_view> split_;   // scratch of split_csv_line
  std::vector<std::size_t> field_begin_;  // the current row's fields as offsets into line_,
  std::vector<std::size_t> field_size_;   // so that a moved reader keeps valid fields
  std::vector<std::string> columns_;
  int line_number_ = 0;
  int header_line_ = 0;       // 0 when the columns are implied
  bool pending_row_ = false;  // the header line turned out to be the first row
};

}  // namespace uh
