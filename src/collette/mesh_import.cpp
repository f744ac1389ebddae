#include "uh/collette/mesh_import.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <system_error>

#include "mesh_file_reader.hpp"
#include "uh/core/regular_file.hpp"

namespace uh::collette {
namespace {

double bbox_diagonal(const std::vector<Vec3>& vertices) {
  if (vertices.empty()) return 0.0;
  Vec3 lo = vertices.front();
  Vec3 hi = lo;
  for (const Vec3& v : vertices) {
    lo = {std::min(lo.x, v.x), std::min(lo.y, v.y), std::min(lo.z, v.z)};
    hi = {std::max(hi.x, v.x), std::max(hi.y, v.y), std::max(hi.z, v.z)};
  }
  return norm(hi - lo);
}

struct CellKey {
  std::int64_t x, y, z;
  bool operator==(const CellKey&) const = default;
};
struct CellHash {
  std::size_t operator()(const CellKey& k) const {
    // spread every input bit over the word (splitmix64 finaliser): the table is indexed by the low bits
    std::uint64_t h = static_cast<std::uint64_t>(k.x) * 0x9E3779B97F4A7C15ULL ^
                      static_cast<std::uint64_t>(k.y) * 0xC2B2AE3D27D4EB4FULL ^
                      static_cast<std::uint64_t>(k.z) * 0x165667B19E3779F9ULL;
    h ^= h >> 31;
    h *= 0xBF58476D1CE4E5B9ULL;
    h ^= h >> 29;
    return static_cast<std::size_t>(h);
  }
};

// Maps every vertex to the lowest-index vertex within `tol` that was itself kept (first come,
// first kept), so the result does not depend on hash-table order.
std::vector<std::int32_t> weld_map(const std::vector<Vec3>& v, double tol) {
  std::vector<std::int32_t> map(v.size());
  // no tolerance (or none a grid can hold: a NaN or infinite one from a huge bounding box) merges
  // bit-identical vertices only
  if (!(tol > 0.0) || !std::isfinite(tol)) {
    std::vector<std::int32_t> order(v.size());
    std::iota(order.begin(), order.end(), 0);
    auto less = [&](std::int32_t a, std::int32_t b) {
      const Vec3& p = v[static_cast<std::size_t>(a)];
      const Vec3& q = v[static_cast<std::size_t>(b)];
      if (p.x != q.x) return p.x < q.x;
      if (p.y != q.y) return p.y < q.y;
      if (p.z != q.z) return p.z < q.z;
      return a < b;
    };
    std::sort(order.begin(), order.end(), less);
    for (std::size_t i = 0; i < order.size(); ++i) {
      const auto cur = static_cast<std::size_t>(order[i]);
      if (i > 0 && v[static_cast<std::size_t>(order[i - 1])] == v[cur]) {
        map[cur] = map[static_cast<std::size_t>(order[i - 1])];
      } else {
        map[cur] = order[i];
      }
    }
    return map;
  }
  // cells of edge `tol` in an open-addressing table (one allocation, no node per cell); each cell
  // heads a list of the kept vertices in it, linked through `next`
  std::size_t capacity = 16;
  while (capacity < 2 * v.size()) capacity *= 2;
  const std::size_t mask = capacity - 1;
  std::vector<CellKey> keys(capacity);
  std::vector<std::int32_t> heads(capacity, -1);
  std::vector<std::int32_t> next(v.size(), -1);
  auto slot_of = [&](const CellKey& k) {
    std::size_t s = CellHash{}(k)&mask;
    while (heads[s] >= 0 && !(keys[s] == k)) s = (s + 1) & mask;
    return s;
  };
  const double tol2 = tol * tol;
  // far vertices share the outermost cells (the distance test below stays exact), so a cell and
  // its neighbours' indices never overflow
  auto cell = [tol](double x) {
    constexpr double kOutermost = 0x1p60;
    return static_cast<std::int64_t>(std::clamp(std::floor(x / tol), -kOutermost, kOutermost));
  };
  for (std::size_t i = 0; i < v.size(); ++i) {
    const CellKey k{cell(v[i].x), cell(v[i].y), cell(v[i].z)};
    std::int32_t found = -1;
    for (std::int64_t dx = -1; dx <= 1; ++dx) {
      for (std::int64_t dy = -1; dy <= 1; ++dy) {
        for (std::int64_t dz = -1; dz <= 1; ++dz) {
          for (std::int32_t j = heads[slot_of({k.x + dx, k.y + dy, k.z + dz})]; j >= 0;
               j = next[static_cast<std::size_t>(j)]) {
            if (squared_norm(v[static_cast<std::size_t>(j)] - v[i]) <= tol2 && (found < 0 || j < found))
              found = j;
          }
        }
      }
    }
    if (found >= 0) {
      map[i] = found;
    } else {
      map[i] = static_cast<std::int32_t>(i);
      const std::size_t s = slot_of(k);
      keys[s] = k;
      next[i] = heads[s];
      heads[s] = static_cast<std::int32_t>(i);
    }
  }
  return map;
}

// Marks in `skip` every triangle on the same three vertices as an earlier one, whatever its
// winding (faces already marked are ignored); the first in file order is kept, and the winding
// check that follows judges it. A double-sided export (every face twice, once reversed) thus
// keeps one side. With `drop` false nothing is marked. Returns the number of such faces.
std::int64_t mark_duplicate_faces(const std::vector<std::array<std::int32_t, 3>>& triangles,
                                  std::vector<char>& skip, bool drop) {
  struct Key {
    std::array<std::int32_t, 3> sorted;
    std::int32_t face;
  };
  std::vector<Key> keys;
  keys.reserve(triangles.size());
  for (std::size_t f = 0; f < triangles.size(); ++f) {
    if (skip[f] != 0) continue;
    auto sorted = triangles[f];
    std::sort(sorted.begin(), sorted.end());
    keys.push_back({sorted, static_cast<std::int32_t>(f)});
  }
  std::sort(keys.begin(), keys.end(), [](const Key& x, const Key& y) {
    return x.sorted < y.sorted || (x.sorted == y.sorted && x.face < y.face);
  });
  std::int64_t duplicates = 0;
  for (std::size_t k = 1; k < keys.size(); ++k) {
    if (keys[k].sorted != keys[k - 1].sorted) continue;
    ++duplicates;
    if (drop) skip[static_cast<std::size_t>(keys[k].face)] = 1;
  }
  return duplicates;
}

std::int32_t find_root(std::vector<std::int32_t>& parent, std::int32_t i) {
  while (parent[static_cast<std::size_t>(i)] != i) {
    parent[static_cast<std::size_t>(i)] =
        parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
    i = parent[static_cast<std::size_t>(i)];
  }
  return i;
}

// Refuses an empty mesh, an index out of range and a non-finite coordinate.
Status check_mesh_input(const TriangleMesh& mesh) {
  const std::string& name = mesh.source_name;
  if (mesh.triangles.empty() || mesh.vertices.empty()) {
    return Error{
        fmt::format("{}: mesh is empty: {} vertices, {} triangles (a closed triangle mesh is required)", name,
                    mesh.vertices.size(), mesh.triangles.size())};
  }
  for (const auto& t : mesh.triangles) {
    for (const std::int32_t i : t) {
      if (i < 0 || static_cast<std::size_t>(i) >= mesh.vertices.size()) {
        return Error{fmt::format("{}: triangle refers to vertex {} but the mesh has {} vertices", name, i,
                                 mesh.vertices.size())};
      }
    }
  }
  for (const Vec3& v : mesh.vertices) {
    if (!is_finite(v)) return Error{fmt::format("{}: mesh has a vertex with a non-finite coordinate", name)};
  }
  return Ok{};
}

// Welds vertices closer than `tolerance`: every index then names the representative of its
// cluster in the input array. Returns how many vertices were merged away.
std::int64_t weld_vertices(TriangleMesh& mesh, double tolerance) {
  const std::vector<std::int32_t> map = weld_map(mesh.vertices, tolerance);
  for (auto& t : mesh.triangles) {
    for (std::int32_t& i : t) i = map[static_cast<std::size_t>(i)];
  }
  std::int64_t distinct_inputs = 0;
  for (std::size_t i = 0; i < map.size(); ++i)
    distinct_inputs += (map[i] == static_cast<std::int32_t>(i)) ? 1 : 0;
  return static_cast<std::int64_t>(mesh.vertices.size()) - distinct_inputs;
}

// Degenerate faces (repeated vertices after welding, or (near) zero area) and duplicate faces:
// counted in `report`, dropped when repairing, else marked in the returned flags so that the edge
// counts leave them out and one bad face is reported once.
std::vector<char> mark_bad_faces(TriangleMesh& mesh, const MeshLoadOptions& options, double diag, MeshReport& report) {
  std::vector<char> skip(mesh.triangles.size(), 0);
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    const auto& t = mesh.triangles[f];
    const Vec3& a = mesh.vertices[static_cast<std::size_t>(t[0])];
    const Vec3& b = mesh.vertices[static_cast<std::size_t>(t[1])];
    const Vec3& c = mesh.vertices[static_cast<std::size_t>(t[2])];
    const bool rep = t[0] == t[1] || t[1] == t[2] || t[0] == t[2];
    const bool tiny = norm(cross(b - a, c - a)) <= options.degenerate_area_tolerance * diag * diag;
    if (rep || tiny) {
      ++report.degenerate_faces;
      skip[f] = 1;
    }
  }
  report.duplicate_faces = mark_duplicate_faces(mesh.triangles, skip, options.repair);
  if (options.repair) {
    std::size_t kept = 0;
    for (std::size_t f = 0; f < mesh.triangles.size(); ++f)
      if (skip[f] == 0) mesh.triangles[kept++] = mesh.triangles[f];
    mesh.triangles.resize(kept);
    skip.assign(kept, 0);
    report.repaired = report.degenerate_faces + report.duplicate_faces > 0;
  }
  return skip;
}

// Drops the vertices no triangle uses and numbers the rest in order of first use.
void compact_vertices(TriangleMesh& mesh) {
  std::vector<std::int32_t> compact(mesh.vertices.size(), -1);
  std::vector<Vec3> vertices;
  for (auto& t : mesh.triangles) {
    for (std::int32_t& i : t) {
      const auto root = static_cast<std::size_t>(i);
      if (compact[root] < 0) {
        compact[root] = static_cast<std::int32_t>(vertices.size());
        vertices.push_back(mesh.vertices[root]);
      }
      i = compact[root];
    }
  }
  mesh.vertices = std::move(vertices);
}

// Edge use counts and directions, by sorting (deterministic, no hashing), into the report's
// boundary, non-manifold and inconsistent edges and its connected components.
void count_edges(const TriangleMesh& mesh, const std::vector<char>& skip, MeshReport& report) {
  struct EdgeUse {
    std::uint64_t key;
    std::int32_t face;
    bool forward;
  };
  std::vector<EdgeUse> uses;
  uses.reserve(mesh.triangles.size() * 3);
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    const auto& t = mesh.triangles[f];
    if (skip[f] != 0) continue;
    for (int e = 0; e < 3; ++e) {
      const std::int32_t a = t[static_cast<std::size_t>(e)];
      const std::int32_t b = t[static_cast<std::size_t>((e + 1) % 3)];
      const auto lo = static_cast<std::uint64_t>(std::min(a, b));
      const auto hi = static_cast<std::uint64_t>(std::max(a, b));
      uses.push_back({(lo << 32) | hi, static_cast<std::int32_t>(f), a < b});
    }
  }
  std::sort(uses.begin(), uses.end(), [](const EdgeUse& x, const EdgeUse& y) {
    return x.key < y.key || (x.key == y.key && x.face < y.face);
  });
  std::vector<std::int32_t> parent(mesh.triangles.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    while (j < uses.size() && uses[j].key == uses[i].key) ++j;
    const std::size_t n = j - i;
    if (n == 1) ++report.boundary_edges;
    if (n >= 3) ++report.non_manifold_edges;
    if (n == 2 && uses[i].forward == uses[i + 1].forward) ++report.inconsistent_edges;
    const std::int32_t first_face = uses[i].face;
    for (auto it = uses.begin() + static_cast<std::ptrdiff_t>(i) + 1;
         it != uses.begin() + static_cast<std::ptrdiff_t>(j); ++it) {
      const std::int32_t ra = find_root(parent, first_face);
      const std::int32_t rb = find_root(parent, it->face);
      if (ra != rb) parent[static_cast<std::size_t>(std::max(ra, rb))] = std::min(ra, rb);
    }
    i = j;
  }
  for (std::size_t f = 0; f < parent.size(); ++f) {
    report.components +=
        (find_root(parent, static_cast<std::int32_t>(f)) == static_cast<std::int32_t>(f)) ? 1 : 0;
  }
}

// Refuses a mesh that is open (beyond what allow_open accepts), not 2-manifold, left with
// unrepaired bad faces, or inconsistently oriented, saying which and the counts.
Status check_topology(const std::string& name, const MeshReport& report, const MeshLoadOptions& options) {
  const bool open_ok = options.allow_open && report.boundary_edges <= options.max_open_boundary_edges;
  const bool unrepaired = !options.repair && report.degenerate_faces + report.duplicate_faces > 0;
  if ((report.boundary_edges > 0 && !open_ok) || report.non_manifold_edges > 0 || unrepaired) {
    const char* what = report.non_manifold_edges > 0 ? "mesh is not 2-manifold"
                       : report.boundary_edges > 0   ? "mesh is not closed"
                                                     : "mesh has degenerate or duplicate faces";
    const std::string repaired = report.repaired
                                     ? fmt::format(" after dropping {} degenerate and {} duplicate faces",
                                                   report.degenerate_faces, report.duplicate_faces)
                                     : std::string();
    const std::string counts = options.repair ? std::string()
                                              : fmt::format(", {} degenerate faces, {} duplicate faces",
                                                            report.degenerate_faces, report.duplicate_faces);
    std::string hint;
    if (options.allow_open && report.boundary_edges > options.max_open_boundary_edges &&
        report.non_manifold_edges == 0)
      hint = fmt::format("; at most {} boundary edges are accepted as open", options.max_open_boundary_edges);
    return Error{fmt::format(
        "{}: {}{}: {} boundary edges, {} non-manifold edges{} (a closed 2-manifold mesh is required{})", name,
        what, repaired, report.boundary_edges, report.non_manifold_edges, counts, hint)};
  }
  if (report.inconsistent_edges > 0) {
    return Error{
        fmt::format("{}: mesh orientation is inconsistent: {} edges where neighbouring triangles run the "
                    "same way (their normals disagree); fix the winding in a modelling tool",
                    name, report.inconsistent_edges)};
  }
  return Ok{};
}

}  // namespace

Result<TriangleMesh> validate_mesh(TriangleMesh mesh, const MeshLoadOptions& options) {
  const std::string& name = mesh.source_name;
  MeshReport report{};
  report.input_vertex_count = static_cast<std::int64_t>(mesh.vertices.size());
  if (auto checked = check_mesh_input(mesh); !checked) return checked.error();
  const double diag = bbox_diagonal(mesh.vertices);
  report.welded_vertices = weld_vertices(mesh, options.weld_tolerance * diag);
  const std::vector<char> skip = mark_bad_faces(mesh, options, diag, report);
  compact_vertices(mesh);
  report.triangle_count = static_cast<std::int64_t>(mesh.triangles.size());
  report.vertex_count = static_cast<std::int64_t>(mesh.vertices.size());
  if (mesh.triangles.empty()) {
    return Error{fmt::format("{}: mesh is empty after dropping {} degenerate and {} duplicate faces", name,
                             report.degenerate_faces, report.duplicate_faces)};
  }
  count_edges(mesh, skip, report);
  if (auto checked = check_topology(name, report, options); !checked) return checked.error();
  report.assumed_open = report.boundary_edges > 0;

  // outward normals: a mesh wound inside out encloses a negative volume
  double volume = mesh_volume(mesh);
  if (volume < 0.0) {
    for (auto& t : mesh.triangles) std::swap(t[1], t[2]);
    volume = -volume;
    report.winding_flipped = true;
  }
  if (!(volume > 0.0)) {
    return Error{fmt::format("{}: mesh encloses no volume ({})", name, volume)};
  }
  report.volume = volume;
  mesh.report = report;
  return mesh;
}

Result<TriangleMesh> load_mesh(const std::filesystem::path& path, const MeshLoadOptions& options) {
  const std::string name = path.filename().string();
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    return Error{fmt::format("{}: file not found (looked for '{}')", name, path.string()), ErrorKind::kFile};
  }
  // a directory, FIFO or device is refused before the mesh library opens it (one would block or
  // never end), and so is a file above the limit
  const auto size = check_regular_file(path, kMaxMeshFileBytes);
  if (!size) return size.error();
  if (*size == 0) {
    return Error{fmt::format("{}: file is empty, no mesh to read", name), ErrorKind::kFile};
  }
  // what the reader refuses is the file (format, syntax); what the validation refuses, the mesh
  auto mesh = read_mesh_file(path);
  if (!mesh) return mesh.error().classified(ErrorKind::kFile);
  auto valid = validate_mesh(std::move(*mesh), options);
  if (!valid) return valid.error().classified(ErrorKind::kMesh);
  return valid;
}

}  // namespace uh::collette
