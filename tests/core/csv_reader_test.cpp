#include "uh/core/csv_reader.hpp"

#include <gtest/gtest.h>

#include "text_mutation.hpp"

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace uh {
namespace {

// reads a whole table the way the project's readers do: header, then every row's numbers
// (column "id" kept as text); returns the error message, or "" with the values in `out`
std::string read_all(const std::string& text, std::vector<std::vector<double>>* out = nullptr,
                     std::span<const std::string_view> implied = {}) {
  std::istringstream in(text);
  CsvReader csv(in, "t.csv");
  if (auto h = csv.read_header(implied); !h) return h.error().message;
  while (true) {
    auto more = csv.next_row();
    if (!more) return more.error().message;
    if (!*more) return "";
    std::vector<double> row;
    for (std::size_t c = 0; c < csv.columns().size(); ++c) {
      if (csv.columns()[c] == "id") continue;
      auto v = csv.number(c);
      if (!v) return v.error().message;
      row.push_back(*v);
    }
    if (out != nullptr) out->push_back(row);
  }
}

TEST(CsvReader, SplitsTrimsAndKeepsEmptyFields) {
  std::vector<std::string_view> f;
  split_csv_line(" a ,\tb\t,,c,\r", f);
  ASSERT_EQ(f.size(), 5u);
  EXPECT_EQ(f[0], "a");
  EXPECT_EQ(f[1], "b");
  EXPECT_EQ(f[2], "");
  EXPECT_EQ(f[3], "c");
  EXPECT_EQ(f[4], "");
  split_csv_line("", f);
  ASSERT_EQ(f.size(), 1u);
  EXPECT_EQ(f[0], "");
}

TEST(CsvReader, ParsesOnlyFiniteNumbers) {
  double v = 7.0;
  EXPECT_TRUE(parse_csv_number(" +1.5e3\r", v));
  EXPECT_EQ(v, 1500.0);
  EXPECT_TRUE(parse_csv_number("-0.25", v));
  EXPECT_EQ(v, -0.25);
  for (const char* bad : {"", " ", "+", "+-1", "++1", "1,2", "1 2", "nan", "inf", "-inf", "1e999", "0x10",
                          "1.2.3", "abc", "1e", "--1"}) {
    v = 7.0;
    EXPECT_FALSE(parse_csv_number(bad, v)) << bad;
    EXPECT_EQ(v, 7.0) << "a failed parse must leave the output alone: " << bad;
  }
}

TEST(CsvReader, ReadsColumnsByNameSkippingCommentsAndBlankLines) {
  const std::string text =
      "# written by hand\n"
      "\n"
      "  # indented comment\n"
      "b, id ,a\r\n"
      "2,first,1\n"
      "   \t\n"
      "4,second,3\r\n";
  std::istringstream in(text);
  CsvReader csv(in, "t.csv");
  ASSERT_TRUE(csv.read_header());
  EXPECT_EQ(csv.line_number(), 4);
  ASSERT_EQ(csv.columns().size(), 3u);
  const std::size_t a = *csv.column("a", "a,b");
  const std::size_t id = *csv.column("id", "a,b");
  EXPECT_EQ(a, 2u);
  EXPECT_FALSE(csv.find_column("c").has_value());
  ASSERT_TRUE(*csv.next_row());
  EXPECT_EQ(csv.line_number(), 5);
  EXPECT_EQ(csv.field(id), "first");
  EXPECT_EQ(*csv.number(a), 1.0);
  ASSERT_TRUE(*csv.next_row());
  EXPECT_EQ(csv.line_number(), 7);
  EXPECT_EQ(*csv.number(a), 3.0);
  EXPECT_FALSE(*csv.next_row());
  EXPECT_FALSE(*csv.next_row());  // stays at the end
}

TEST(CsvReader, ImpliedColumnsWhenTheFirstLineIsData) {
  static constexpr std::array<std::string_view, 2> kImplied = {"t", "x"};
  std::vector<std::vector<double>> rows;
  EXPECT_EQ(read_all("# no header\n1,2\n3,4\n", &rows, kImplied), "");
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0], (std::vector<double>{1, 2}));
  EXPECT_EQ(rows[1], (std::vector<double>{3, 4}));
  // a header is still read by name when present
  rows.clear();
  EXPECT_EQ(read_all("x,t\n5,6\n", &rows, kImplied), "");
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0], (std::vector<double>{5, 6}));
  EXPECT_EQ(read_all("1,2,3\n", nullptr, kImplied), "t.csv:1: found 3 fields, expected 2 (t,x)");
}

TEST(CsvReader, MalformedInputGivesErrorsNamingFileLineAndColumn) {
  EXPECT_EQ(read_all(""), "t.csv: no header line (the file is empty or holds only comments)");
  EXPECT_EQ(read_all("# only\n\n"), "t.csv: no header line (the file is empty or holds only comments)");
  EXPECT_EQ(read_all("a,b,a\n"), "t.csv:1: the header names column 'a' twice (fields 1 and 3)");
  EXPECT_EQ(read_all("a,b\n1,2\n1\n"),
            "t.csv:3: found 1 fields, expected 2 as named by the header on line 1");
  EXPECT_EQ(read_all("a,b\n1,2,\n"), "t.csv:2: found 3 fields, expected 2 as named by the header on line 1");
  EXPECT_EQ(read_all("# c\na,b\n\n1,x\n"), "t.csv:4: column 'b' (field 2) is 'x', expected a finite number");
  EXPECT_EQ(read_all("a,b\n1,\n"), "t.csv:2: column 'b' (field 2) is '', expected a finite number");
  EXPECT_EQ(read_all("a,b\nnan,1\n"), "t.csv:2: column 'a' (field 1) is 'nan', expected a finite number");
  EXPECT_EQ(read_all("a,b\n1e400,1\n"), "t.csv:2: column 'a' (field 1) is '1e400', expected a finite number");
  std::istringstream in("a,b\n");
  CsvReader csv(in, "t.csv");
  ASSERT_TRUE(csv.read_header());
  EXPECT_EQ(csv.column("qz", "a,b,qz").error().message,
            "t.csv:1: the header lacks column 'qz' (expected columns a,b,qz)");
}

TEST(CsvReader, OpenNamesTheFileAndTheReason) {
  auto r = CsvReader::open("/nonexistent-uh/poses.csv", "pose file");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().message,
            "/nonexistent-uh/poses.csv: cannot open the pose file (No such file or directory)");
}

TEST(CsvReader, AMovedReaderKeepsItsFields) {
  const std::filesystem::path path = std::filesystem::temp_directory_path() / "uh_csv_reader_move_test.csv";
  std::ofstream(path) << "a\n12\n";
  auto opened = CsvReader::open(path, "test file");
  ASSERT_TRUE(opened) << opened.error().message;
  ASSERT_TRUE(opened->read_header());
  ASSERT_TRUE(*opened->next_row());
  CsvReader moved = std::move(*opened);
  EXPECT_EQ(moved.field(0), "12");
  EXPECT_FALSE(*moved.next_row());
  std::filesystem::remove(path);
}

TEST(CsvReader, RandomEditsEitherParseOrNameTheFileAndLine) {
  // property: any mutation of a valid table gives rows of finite numbers, or an error that
  // starts with "t.csv:" and, past the header, a line number within the text
  const std::string valid = "# c\nid,a,b\nx,1,2.5\ny,-3,4e2\n\nz,5,6\n";
  const std::string alphabet = "0123456789.,-+eE\n\r #abinf\t";
  core::SplitMix64 rng{29};
  int errors = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const std::string text = test::mutate_text(valid, alphabet, rng);
    std::vector<std::vector<double>> rows;
    const std::string message = read_all(text, &rows);
    if (!message.empty()) {
      ++errors;
      EXPECT_EQ(message.rfind("t.csv:", 0), 0u) << message;
      continue;
    }
    for (const auto& row : rows)
      for (const double v : row) EXPECT_TRUE(std::isfinite(v));
  }
  EXPECT_GT(errors, 300);
}

}  // namespace
}  // namespace uh
