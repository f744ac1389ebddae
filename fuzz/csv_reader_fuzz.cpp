// libFuzzer target for the CSV reader (replayed trajectories and traces, pose lists, device
// settings all go through it, and all may come from someone else's machine): any bytes must give
// rows or an error that starts with the source name and a line number, never a crash, an
// uncaught exception or a hang. Seeds: fuzz/csv_seeds (scripts/test.sh passes it read-only).

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>
#include <string_view>

#include "uh/core/csv_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  static constexpr std::array<std::string_view, 3> kImplied = {"time_s", "x", "id"};
  // both header modes: read by name, and implied columns when the first line is data
  for (const bool implied : {false, true}) {
    std::istringstream in(text);
    uh::CsvReader csv(in, "fuzz.csv");
    auto header = implied ? csv.read_header(kImplied) : csv.read_header();
    if (!header) {
      if (header.error().message.rfind("fuzz.csv:", 0) != 0) std::abort();
      continue;
    }
    if (csv.columns().empty()) std::abort();
    const auto x = csv.find_column("x");
    while (true) {
      auto more = csv.next_row();
      if (!more) {
        if (more.error().message.rfind("fuzz.csv:", 0) != 0) std::abort();
        break;
      }
      if (!*more) break;
      for (std::size_t c = 0; c < csv.columns().size(); ++c) {
        const std::string_view f = csv.field(c);
        // fields are trimmed and never hold the separator or a line break
        if (f.find(',') != std::string_view::npos || f.find('\n') != std::string_view::npos) std::abort();
        if (!f.empty() && (f.front() == ' ' || f.back() == ' ' || f.back() == '\r')) std::abort();
      }
      if (x) {
        auto v = csv.number(*x);
        if (v ? !std::isfinite(*v) : v.error().message.rfind("fuzz.csv:", 0) != 0) std::abort();
      }
    }
  }
  return 0;
}
