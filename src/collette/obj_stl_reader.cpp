// The in-tree mesh reader (read_obj_or_stl): what load_mesh() reads in builds without assimp (the
// Windows build), and tested against assimp where both exist. Coordinates are rounded to float, as
// assimp stores them, so that both readers give the same mesh and the same sphere packing.

#include <fmt/format.h>
#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "mesh_file_reader.hpp"
#include "uh/collette/mesh_import.hpp"
#include "uh/core/regular_file.hpp"

namespace uh::collette {
namespace {

constexpr std::size_t kStlHeaderBytes = 80;
constexpr std::size_t kStlTriangleBytes = 50;  // normal, three vertices (12 floats), attribute (2 bytes)

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

// the whitespace-separated words of a line
class Words {
 public:
  explicit Words(std::string_view line) : rest_(line) {}
  // the next word, or an empty view at the end
  std::string_view next() {
    std::size_t i = 0;
    while (i < rest_.size() && is_space(rest_[i])) ++i;
    std::size_t j = i;
    while (j < rest_.size() && !is_space(rest_[j])) ++j;
    const std::string_view word = rest_.substr(i, j - i);
    rest_.remove_prefix(j);
    return word;
  }

 private:
  std::string_view rest_;
};

std::string lower(std::string_view text) {
  std::string out(text);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

bool parse_double(std::string_view word, double& value) {
  if (!word.empty() && word.front() == '+') word.remove_prefix(1);
  const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), value);
  return ec == std::errc{} && end == word.data() + word.size();
}

// a coordinate as assimp keeps it: a float
bool parse_coordinate(std::string_view word, double& value) {
  if (!parse_double(word, value)) return false;
  value = static_cast<double>(static_cast<float>(value));
  return true;
}

// the three coordinates after `v` or `vertex`; false with `error` saying what is wrong
bool parse_vertex(Words& words, Vec3& p, std::string& error) {
  for (double* c : {&p.x, &p.y, &p.z}) {
    const std::string_view word = words.next();
    if (word.empty()) {
      error = "a vertex needs 3 coordinates";
      return false;
    }
    if (!parse_coordinate(word, *c)) {
      error = fmt::format("vertex coordinate '{}' is not a number", word);
      return false;
    }
  }
  return true;
}

// calls on_line(line_number, line) for every line of `text` (LF or CRLF)
template <typename F>
bool for_each_line(std::string_view text, F&& on_line) {
  std::size_t number = 0;
  while (!text.empty()) {
    const std::size_t end = std::min(text.find('\n'), text.size());
    if (!on_line(++number, text.substr(0, end))) return false;
    text.remove_prefix(std::min(end + 1, text.size()));
  }
  return true;
}

// OBJ: `v x y z [w]` and `f a b c ...` (a = i, i/t, i//n or i/t/n; negative i counts back from
// the last vertex so far); faces with more than three corners are fanned from their first corner
Result<TriangleMesh> read_obj(std::string_view text, const std::string& name) {
  TriangleMesh mesh;
  mesh.source_name = name;
  std::string error;
  std::vector<std::int32_t> corners;
  const bool ok = for_each_line(text, [&](std::size_t number, std::string_view line) {
    Words words(line);
    const std::string_view keyword = words.next();
    if (keyword == "v") {
      Vec3 p{};
      if (!parse_vertex(words, p, error)) {
        error = fmt::format("{}:{}: {}", name, number, error);
        return false;
      }
      mesh.vertices.push_back(p);
    } else if (keyword == "f") {
      corners.clear();
      for (std::string_view word = words.next(); !word.empty(); word = words.next()) {
        const std::string_view index_text = word.substr(0, word.find('/'));
        long long index = 0;
        const auto [end, ec] =
            std::from_chars(index_text.data(), index_text.data() + index_text.size(), index);
        const auto defined = static_cast<long long>(mesh.vertices.size());
        if (ec != std::errc{} || end != index_text.data() + index_text.size() || index == 0) {
          error = fmt::format("{}:{}: face corner '{}' is not a vertex number", name, number, word);
          return false;
        }
        if (index < 0 ? -index > defined : index > INT32_MAX) {
          error =
              fmt::format("{}:{}: face corner {} refers to a vertex that does not exist ({} defined so far)",
                          name, number, index, defined);
          return false;
        }
        // a positive index past the vertices so far is left to validate_mesh(), which names it
        corners.push_back(static_cast<std::int32_t>(index < 0 ? defined + index : index - 1));
      }
      if (corners.size() < 3) {
        error = fmt::format("{}:{}: a face needs at least 3 corners, this one has {}", name, number,
                            corners.size());
        return false;
      }
      for (std::size_t i = 1; i + 1 < corners.size(); ++i)
        mesh.triangles.push_back({corners[0], corners[i], corners[i + 1]});
    }
    // normals, texture coordinates, groups, materials, lines, points: no surface to read
    return true;
  });
  if (!ok) return Error{error};
  return mesh;
}

// ASCII STL: `facet` ... `outer loop` `vertex x y z` (three) `endloop` `endfacet`
Result<TriangleMesh> read_ascii_stl(std::string_view text, const std::string& name) {
  TriangleMesh mesh;
  mesh.source_name = name;
  std::string error;
  int in_facet = -1;  // vertices read in the current facet, -1 outside a facet
  const bool ok = for_each_line(text, [&](std::size_t number, std::string_view line) {
    Words words(line);
    const std::string keyword = lower(words.next());
    if (keyword == "facet") {
      in_facet = 0;
    } else if (keyword == "vertex") {
      if (in_facet < 0 || in_facet >= 3) {
        error = fmt::format("{}:{}: a vertex outside a facet, or a facet with more than 3 vertices", name,
                            number);
        return false;
      }
      Vec3 p{};
      if (!parse_vertex(words, p, error)) {
        error = fmt::format("{}:{}: {}", name, number, error);
        return false;
      }
      mesh.vertices.push_back(p);
      ++in_facet;
    } else if (keyword == "endfacet") {
      if (in_facet != 3) {
        error =
            fmt::format("{}:{}: a facet with {} vertices (3 expected)", name, number, std::max(in_facet, 0));
        return false;
      }
      const auto first = static_cast<std::int32_t>(mesh.vertices.size() - 3);
      mesh.triangles.push_back({first, first + 1, first + 2});
      in_facet = -1;
    }
    return true;
  });
  if (!ok) return Error{error};
  if (in_facet >= 0) return Error{fmt::format("{}: the file ends inside a facet", name)};
  return mesh;
}

Result<TriangleMesh> read_binary_stl(std::string_view bytes, std::uint32_t count, const std::string& name) {
  static_assert(std::endian::native == std::endian::little,
                "binary STL is little-endian: byte swapping needed here");
  TriangleMesh mesh;
  mesh.source_name = name;
  mesh.vertices.reserve(std::size_t{3} * count);
  mesh.triangles.reserve(count);
  const char* p = bytes.data() + kStlHeaderBytes + 4;
  for (std::uint32_t t = 0; t < count; ++t, p += kStlTriangleBytes) {
    float v[9];
    std::memcpy(v, p + 12, sizeof(v));  // after the facet normal, which is recomputed from the winding
    const auto first = static_cast<std::int32_t>(mesh.vertices.size());
    for (int k = 0; k < 3; ++k) {
      mesh.vertices.push_back({static_cast<double>(v[3 * k]), static_cast<double>(v[3 * k + 1]),
                               static_cast<double>(v[3 * k + 2])});
    }
    mesh.triangles.push_back({first, first + 1, first + 2});
  }
  return mesh;
}

Result<TriangleMesh> read_stl(std::string_view bytes, const std::string& name) {
  // binary whenever the size fits the triangle count exactly: binary files may begin with "solid" too
  if (bytes.size() >= kStlHeaderBytes + 4) {
    std::uint32_t count = 0;
    std::memcpy(&count, bytes.data() + kStlHeaderBytes, 4);
    if (bytes.size() == kStlHeaderBytes + 4 + kStlTriangleBytes * std::size_t{count}) {
      return read_binary_stl(bytes, count, name);
    }
  }
  Words first(bytes.substr(0, std::min<std::size_t>(bytes.size(), 256)));
  if (lower(first.next()) != "solid") {
    return Error{
        fmt::format("{}: cannot read mesh: neither a binary STL (its size does not match its triangle "
                    "count) nor an ASCII STL (it does not begin with 'solid')",
                    name)};
  }
  return read_ascii_stl(bytes, name);
}

}  // namespace

bool is_obj_or_stl(const std::filesystem::path& path) {
  const std::string extension = lower(path.extension().string());
  return extension == ".obj" || extension == ".stl";
}

Result<TriangleMesh> parse_obj_or_stl(std::string_view bytes, const std::string& name) {
  const std::filesystem::path path(name);
  if (!is_obj_or_stl(path)) {
    return Error{fmt::format(
        "{}: cannot read mesh: the built-in reader reads OBJ (.obj) and STL (.stl) files only", name)};
  }
  return lower(path.extension().string()) == ".obj" ? read_obj(bytes, name) : read_stl(bytes, name);
}

Result<TriangleMesh> read_obj_or_stl(const std::filesystem::path& path) {
  const std::string name = path.filename().string();
  if (!is_obj_or_stl(path)) return parse_obj_or_stl({}, name);  // the error naming the formats
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return Error{fmt::format("{}: cannot open the mesh file", name)};
  auto bytes = read_regular_file(path, kMaxMeshFileBytes);
  if (!bytes) return bytes.error();
  return parse_obj_or_stl(*bytes, name);
}

std::string obj_text(const TriangleMesh& mesh, std::string_view comment) {
  std::string obj;
  if (!comment.empty()) obj = fmt::format("# {}\n", comment);
  // {} prints the shortest text that reads back to the same double
  for (const Vec3& v : mesh.vertices) obj += fmt::format("v {} {} {}\n", v.x, v.y, v.z);
  for (const auto& t : mesh.triangles) obj += fmt::format("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
  return obj;
}

}  // namespace uh::collette
