#include "uh/collette/ist_file.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <tuple>

#include "uh/collette/mesh_import.hpp"
#include "uh/core/atomic_file_writer.hpp"
#include "uh/core/regular_file.hpp"

namespace uh::collette {
namespace {

constexpr std::array<unsigned char, 8> kMagic{'U', 'H', 'I', 'S', 'T', '\r', '\n', 0x1a};
constexpr std::size_t kNodeBytes = 32;
constexpr std::size_t kLeafBytes = 16;
// surface section: u32 vertex count, u32 triangle count, the vertices (3 f64), the triangles
// (3 i32), then the CRC-32 of all the section's bytes before it
constexpr std::size_t kSurfaceCountBytes = 8, kSurfaceCrcBytes = 4, kVertexBytes = 24, kTriangleBytes = 12;
// a closed surface has at least a tetrahedron's 4 vertices and 4 triangles
constexpr std::uint64_t kMinSurfaceCount = 4;
// the volume a stored surface encloses against IstMetadata::mesh_volume (the same mesh summed
// again, maybe scaled)
constexpr double kSurfaceVolumeTolerance = 1e-6;
// header field offsets [bytes]
constexpr std::size_t kOffVersion = 8, kOffHeaderSize = 12, kOffNodes = 16, kOffLeaves = 20, kOffDepth = 24,
                      kOffArity = 28, kOffMetersPerUnit = 32, kOffMeshHash = 40, kOffCoverage = 48,
                      kOffMeshVolume = 56, kOffMaxGap = 64, kOffBuildSeconds = 72, kOffSphereCount = 80,
                      kOffFlags = 84, kOffPayloadBytes = 88, kOffPayloadCrc = 96, kOffHeaderCrc = 100,
                      kOffReserved = 104;
// a .ist above this size is refused before reading it into memory
constexpr std::uintmax_t kMaxFileBytes = std::uintmax_t{1} << 31;

std::array<std::uint32_t, 256> make_crc_table() {
  std::array<std::uint32_t, 256> t{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    t[i] = c;
  }
  return t;
}

void put_u32(std::byte* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::byte>((v >> (8 * i)) & 0xffu);
}
void put_u64(std::byte* p, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<std::byte>((v >> (8 * i)) & 0xffu);
}
void put_f32(std::byte* p, float v) { put_u32(p, std::bit_cast<std::uint32_t>(v)); }
void put_f64(std::byte* p, double v) { put_u64(p, std::bit_cast<std::uint64_t>(v)); }
void put_i32(std::byte* p, std::int32_t v) { put_u32(p, static_cast<std::uint32_t>(v)); }

std::uint32_t get_u32(const std::byte* p) {
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(p[i]) << (8 * i);
  return v;
}
std::uint64_t get_u64(const std::byte* p) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= static_cast<std::uint64_t>(p[i]) << (8 * i);
  return v;
}
float get_f32(const std::byte* p) { return std::bit_cast<float>(get_u32(p)); }
double get_f64(const std::byte* p) { return std::bit_cast<double>(get_u64(p)); }
std::int32_t get_i32(const std::byte* p) { return static_cast<std::int32_t>(get_u32(p)); }

std::string str(std::string_view s) { return std::string(s); }

// shortest text that reads back as the same double (-1, nan, 1e-300; not to_string's fixed 6 digits)
std::string num(double v) {
  std::array<char, 32> buf{};
  for (int digits = 6; digits <= 17; ++digits) {
    std::snprintf(buf.data(), buf.size(), "%.*g", digits, v);
    if (!std::isfinite(v) || std::strtod(buf.data(), nullptr) == v) break;
  }
  return buf.data();
}

// derived figures in messages: six digits are enough to act on
std::string approx(double v) {
  std::array<char, 32> buf{};
  std::snprintf(buf.data(), buf.size(), "%.6g", v);
  return buf.data();
}

// a leaf radius below this fraction of its centre's largest coordinate is refused: the centre
// cannot be stored that precisely, and it bounds the grid cell indices below
constexpr double kMinRadiusPerCoordinate = 1e-9;

// A leaf's place in one radius class's grid (see check_leaves_disjoint)
struct GridEntry {
  int level;
  std::int64_t x, y, z;
  std::int32_t id;
  auto key() const { return std::tie(level, x, y, z); }
};

std::int64_t grid_cell(float c, int level) {
  return static_cast<std::int64_t>(std::floor(static_cast<double>(c) / std::ldexp(4.0, level)));
}

// An error when leaves i and j overlap by more than `tol`
Status check_leaf_pair(std::span<const Sphere> leaves, std::size_t i, std::size_t j, double tol) {
  const Sphere& s = leaves[i];
  const Sphere& t = leaves[j];
  const double dx = static_cast<double>(s.x) - static_cast<double>(t.x);
  const double dy = static_cast<double>(s.y) - static_cast<double>(t.y);
  const double dz = static_cast<double>(s.z) - static_cast<double>(t.z);
  const double depth =
      static_cast<double>(s.radius) + static_cast<double>(t.radius) - std::sqrt(dx * dx + dy * dy + dz * dz);
  if (depth > tol)
    return Error{"invalid tree: leaf spheres " + std::to_string(std::min(i, j)) + " and " +
                 std::to_string(std::max(i, j)) + " overlap by " + approx(depth) +
                 " (the leaves of a packing are disjoint; tolerance " + approx(tol) + ")"};
  return Ok{};
}

// The first two leaf spheres that overlap by more than `tol`. One uniform grid per power-of-two
// radius class (radius in [2^e, 2^(e+1)), cells 2^(e+2) wide, so at least twice the class's
// largest radius): a sphere can only overlap a sphere of its own or a larger class whose centre
// lies in one of the 27 cells around its own centre in that class's grid. Spheres of a packing
// are disjoint, so a cell holds a bounded number of them and the check is O(n log n) even for
// a hostile file (a quadratic sweep would not be). The entries are sorted with z last, so the
// three cells of a column (dx, dy) are one run found by one binary search.
Status check_leaves_disjoint(std::span<const Sphere> leaves, double tol) {
  std::vector<GridEntry> entries;
  entries.reserve(leaves.size());
  for (std::size_t i = 0; i < leaves.size(); ++i) {
    const Sphere& s = leaves[i];
    const int level = std::ilogb(s.radius);
    entries.push_back({level, grid_cell(s.x, level), grid_cell(s.y, level), grid_cell(s.z, level),
                       static_cast<std::int32_t>(i)});
  }
  std::sort(entries.begin(), entries.end(), [](const GridEntry& a, const GridEntry& b) {
    return a.key() < b.key() || (a.key() == b.key() && a.id < b.id);
  });
  std::vector<int> levels;
  for (const GridEntry& e : entries)
    if (levels.empty() || levels.back() != e.level) levels.push_back(e.level);
  const auto by_key = [](const GridEntry& a, const GridEntry& b) { return a.key() < b.key(); };
  for (std::size_t i = 0; i < leaves.size(); ++i) {
    const Sphere& s = leaves[i];
    for (auto lv = std::lower_bound(levels.begin(), levels.end(), std::ilogb(s.radius)); lv != levels.end(); ++lv) {
      const std::int64_t cx = grid_cell(s.x, *lv), cy = grid_cell(s.y, *lv), cz = grid_cell(s.z, *lv);
      for (std::int64_t dx = -1; dx <= 1; ++dx)
        for (std::int64_t dy = -1; dy <= 1; ++dy) {
          const GridEntry first{*lv, cx + dx, cy + dy, cz - 1, -1};
          for (auto it = std::lower_bound(entries.begin(), entries.end(), first, by_key);
               it != entries.end() && it->level == *lv && it->x == cx + dx && it->y == cy + dy && it->z <= cz + 1;
               ++it) {
            const auto j = static_cast<std::size_t>(it->id);
            if (j == i) continue;
            if (Status ok = check_leaf_pair(leaves, i, j, tol); !ok) return ok;
          }
        }
    }
  }
  return Ok{};
}

// The surface a packing's spheres lie in: closed, 2-manifold and outward as stored (the mesh
// validator, with no welding and no repair, drops nothing and turns nothing), enclosing the
// metadata's volume, with the leaves inside its bounding box.
Status check_surface(const TriangleMesh& surface, const IstAsset& asset) {
  TriangleMesh named = surface;
  named.source_name = "invalid surface section";
  auto valid = validate_mesh(std::move(named), {.weld_tolerance = 0.0, .repair = false});
  if (!valid) return valid.error();
  if (valid->report.winding_flipped)
    return Error{"invalid surface section: it is wound inside out (a .ist holds its surface wound outward)"};
  // with no welding and no repair the validator only merges bit-identical vertices and drops unused
  // ones (and numbers the rest by first use, which is no fault)
  if (valid->vertices.size() != surface.vertices.size())
    return Error{"invalid surface section: it repeats a vertex or has one no triangle uses (" +
                 std::to_string(surface.vertices.size()) + " stored, " + std::to_string(valid->vertices.size()) +
                 " distinct and used)"};
  const double volume = mesh_volume(surface);
  if (!(std::abs(volume - asset.meta.mesh_volume) <= kSurfaceVolumeTolerance * asset.meta.mesh_volume))
    return Error{"invalid surface section: it encloses " + approx(volume) + ", but mesh_volume is " +
                 approx(asset.meta.mesh_volume)};
  const Aabb box = mesh_bounds(surface);
  const auto leaves = asset.tree.leaves();
  const double tol = 1e-5 * static_cast<double>(asset.tree.root().radius);
  for (std::size_t i = 0; i < leaves.size(); ++i) {
    const Sphere& s = leaves[i];
    const Vec3 c{static_cast<double>(s.x), static_cast<double>(s.y), static_cast<double>(s.z)};
    const Vec3 r{static_cast<double>(s.radius) - tol, static_cast<double>(s.radius) - tol,
                 static_cast<double>(s.radius) - tol};
    const Vec3 lo = c - r, hi = c + r;
    if (lo.x < box.min.x || lo.y < box.min.y || lo.z < box.min.z || hi.x > box.max.x || hi.y > box.max.y ||
        hi.z > box.max.z)
      return Error{"invalid surface section: leaf sphere " + std::to_string(i) +
                   " reaches outside the surface's bounding box (the spheres were packed inside it)"};
  }
  return Ok{};
}

Error meta_error(const char* field, double value, const std::string& expected) {
  return Error{std::string("invalid metadata: ") + field + " is " + num(value) + ", expected " + expected};
}

std::size_t surface_section_bytes(const TriangleMesh& surface) {
  return kSurfaceCountBytes + surface.vertices.size() * kVertexBytes + surface.triangles.size() * kTriangleBytes +
         kSurfaceCrcBytes;
}

// writes the surface section at `p` (surface_section_bytes(surface) bytes)
void put_surface_section(std::byte* p, const TriangleMesh& surface) {
  std::byte* const start = p;
  put_u32(p, static_cast<std::uint32_t>(surface.vertices.size()));
  put_u32(p + 4, static_cast<std::uint32_t>(surface.triangles.size()));
  p += kSurfaceCountBytes;
  for (const Vec3& v : surface.vertices) {
    put_f64(p + 0, v.x);
    put_f64(p + 8, v.y);
    put_f64(p + 16, v.z);
    p += kVertexBytes;
  }
  for (const auto& t : surface.triangles) {
    for (int k = 0; k < 3; ++k) put_i32(p + 4 * k, t[static_cast<std::size_t>(k)]);
    p += kTriangleBytes;
  }
  put_u32(p, ist_crc32({start, static_cast<std::size_t>(p - start)}));
}

// Reads the surface section `section` (the bytes after the leaves), checking its counts against
// its size before allocating and its checksum; `size` is the whole file's, for messages.
Result<TriangleMesh> get_surface_section(std::span<const std::byte> section, std::size_t size) {
  const std::size_t before = size - section.size();
  if (section.size() < kSurfaceCountBytes + kSurfaceCrcBytes)
    return Error{"truncated: " + std::to_string(size) + " bytes, but the surface section's counts and checksum need " +
                 std::to_string(before + kSurfaceCountBytes + kSurfaceCrcBytes)};
  const std::byte* p = section.data();
  const std::uint64_t vertices = get_u32(p), triangles = get_u32(p + 4);
  if (triangles < kMinSurfaceCount || triangles > kIstMaxSurfaceTriangles || vertices < kMinSurfaceCount ||
      vertices > triangles)
    return Error{"corrupted: a surface section of " + std::to_string(vertices) + " vertices and " +
                 std::to_string(triangles) + " triangles (a closed surface has 4 .. " +
                 std::to_string(kIstMaxSurfaceTriangles) + " triangles and 4 .. as many vertices)"};
  const std::uint64_t expected =
      kSurfaceCountBytes + vertices * kVertexBytes + triangles * kTriangleBytes + kSurfaceCrcBytes;
  if (section.size() < expected)
    return Error{"truncated: " + std::to_string(size) + " bytes, the header and the surface section announce " +
                 std::to_string(before + expected)};
  if (section.size() > expected)
    return Error{"corrupted: " + std::to_string(section.size() - expected) +
                 " unexpected bytes after the surface section"};
  const std::size_t checked = section.size() - kSurfaceCrcBytes;
  if (get_u32(p + checked) != ist_crc32({p, checked})) return Error{"corrupted: surface section checksum mismatch"};
  TriangleMesh surface;
  surface.vertices.resize(static_cast<std::size_t>(vertices));
  surface.triangles.resize(static_cast<std::size_t>(triangles));
  p += kSurfaceCountBytes;
  for (Vec3& v : surface.vertices) {
    v = {get_f64(p + 0), get_f64(p + 8), get_f64(p + 16)};
    p += kVertexBytes;
  }
  for (auto& t : surface.triangles) {
    t = {get_i32(p + 0), get_i32(p + 4), get_i32(p + 8)};
    p += kTriangleBytes;
  }
  return surface;
}

}  // namespace

std::uint32_t ist_crc32(std::span<const std::byte> bytes) {
  static const std::array<std::uint32_t, 256> table = make_crc_table();
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::byte b : bytes) c = table[(c ^ static_cast<std::uint32_t>(b)) & 0xffu] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

std::uint64_t ist_hash_bytes(std::span<const std::byte> bytes) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (std::byte b : bytes) {
    h ^= static_cast<std::uint64_t>(b);
    h *= 0x100000001b3ull;
  }
  return h;
}

Status validate(const IstAsset& asset) {
  const SphereTree& tree = asset.tree;
  if (const Status ok = validate(tree); !ok) return Error{"invalid tree: " + ok.error().message};
  for (int c = 0; c < tree.node_count(); ++c)
    if (tree.nodes()[static_cast<std::size_t>(c)].count > tree.arity())
      return Error{"invalid tree: node " + std::to_string(c) + " has more children than the arity " +
                   std::to_string(tree.arity())};
  const IstMetadata& m = asset.meta;
  if (!(m.meters_per_unit >= kIstMinMetersPerUnit && m.meters_per_unit <= kIstMaxMetersPerUnit))
    return meta_error("meters_per_unit", m.meters_per_unit,
                      "the length of one mesh unit in metres, " + approx(kIstMinMetersPerUnit) + " .. " +
                          approx(kIstMaxMetersPerUnit));
  if (!(std::isfinite(m.mesh_volume) && m.mesh_volume > 0.0))
    return meta_error("mesh_volume", m.mesh_volume, "a finite positive volume");
  if (!(m.coverage > 0.0 && m.coverage <= 1.0))
    return meta_error("coverage", m.coverage, "a fraction in (0, 1]");
  const double filled = tree.total_volume() / m.mesh_volume;
  if (!(std::abs(filled - m.coverage) <= kIstCoverageTolerance * m.coverage))
    return meta_error("coverage", m.coverage,
                      "the spheres' volume " + approx(tree.total_volume()) + " / mesh_volume " +
                          approx(m.mesh_volume) + " = " + approx(filled));
  if (!(std::isfinite(m.max_gap) && m.max_gap >= 0.0))
    return meta_error("max_gap", m.max_gap, "a finite length >= 0");
  if (!(std::isfinite(m.build_seconds) && m.build_seconds >= 0.0))
    return meta_error("build_seconds", m.build_seconds, "a finite time >= 0");
  const auto leaves = tree.leaves();
  for (std::size_t i = 0; i < leaves.size(); ++i) {
    const Sphere& s = leaves[i];
    const float far = std::max({std::abs(s.x), std::abs(s.y), std::abs(s.z)});
    if (static_cast<double>(s.radius) < kMinRadiusPerCoordinate * static_cast<double>(far))
      return Error{"invalid tree: leaf sphere " + std::to_string(i) + " has radius " +
                   approx(static_cast<double>(s.radius)) + ", below 1e-9 of its centre's coordinate " +
                   approx(static_cast<double>(far)) + " (a float centre is not that precise)"};
  }
  if (Status ok = check_leaves_disjoint(leaves, 1e-5 * static_cast<double>(tree.root().radius)); !ok) return ok;
  if (asset.surface) return check_surface(*asset.surface, asset);
  return Ok{};
}

std::vector<std::byte> encode_ist(const IstAsset& asset) {
  const auto nodes = asset.tree.nodes();
  const auto leaves = asset.tree.leaves();
  const std::size_t payload = nodes.size() * kNodeBytes + leaves.size() * kLeafBytes;
  const std::size_t section = asset.surface ? surface_section_bytes(*asset.surface) : 0;
  std::array<std::byte, kIstHeaderSize> header{};
  std::vector<std::byte> body(payload + section, std::byte{0});
  std::byte* h = header.data();
  std::memcpy(h, kMagic.data(), kMagic.size());
  // the oldest version that holds the asset: older builds read a file without a surface
  put_u32(h + kOffVersion, asset.surface ? 2u : 1u);
  put_u32(h + kOffHeaderSize, static_cast<std::uint32_t>(kIstHeaderSize));
  put_u32(h + kOffNodes, static_cast<std::uint32_t>(nodes.size()));
  put_u32(h + kOffLeaves, static_cast<std::uint32_t>(leaves.size()));
  put_u32(h + kOffDepth, static_cast<std::uint32_t>(asset.tree.depth()));
  put_u32(h + kOffArity, static_cast<std::uint32_t>(asset.tree.arity()));
  put_f64(h + kOffMetersPerUnit, asset.meta.meters_per_unit);
  put_u64(h + kOffMeshHash, asset.meta.source_mesh_hash);
  put_f64(h + kOffCoverage, asset.meta.coverage);
  put_f64(h + kOffMeshVolume, asset.meta.mesh_volume);
  put_f64(h + kOffMaxGap, asset.meta.max_gap);
  put_f64(h + kOffBuildSeconds, asset.meta.build_seconds);
  put_u32(h + kOffSphereCount, static_cast<std::uint32_t>(leaves.size()));
  put_u32(h + kOffFlags, asset.surface ? kIstFlagSurface : 0u);
  put_u64(h + kOffPayloadBytes, payload);
  std::byte* p = body.data();
  for (const SphereTreeNode& n : nodes) {
    put_f32(p + 0, n.x);
    put_f32(p + 4, n.y);
    put_f32(p + 8, n.z);
    put_f32(p + 12, n.radius);
    put_f32(p + 16, n.volume);
    put_i32(p + 20, n.first);
    put_i32(p + 24, n.count);
    put_i32(p + 28, n.parent);
    p += kNodeBytes;
  }
  for (const Sphere& s : leaves) {
    put_f32(p + 0, s.x);
    put_f32(p + 4, s.y);
    put_f32(p + 8, s.z);
    put_f32(p + 12, s.radius);
    p += kLeafBytes;
  }
  if (asset.surface) put_surface_section(p, *asset.surface);
  put_u32(h + kOffPayloadCrc, ist_crc32({body.data(), payload}));
  put_u32(h + kOffHeaderCrc, ist_crc32({h, kOffHeaderCrc}));
  body.insert(body.begin(), header.begin(), header.end());
  return body;
}

Result<IstAsset> load_ist_from_memory(std::span<const std::byte> bytes, std::string_view name) {
  const std::string who = str(name) + ": ";
  const std::size_t size = bytes.size();
  const std::byte* h = bytes.data();
  const std::size_t magic_len = std::min(size, kMagic.size());
  if (magic_len == 0 || std::memcmp(h, kMagic.data(), magic_len) != 0)
    return Error{who + "not a .ist sphere-tree file (wrong magic bytes)"};
  if (size < kIstHeaderSize)
    return Error{who + "truncated: " + std::to_string(size) + " bytes, but the .ist header alone has " +
                 std::to_string(kIstHeaderSize)};
  const std::uint32_t version = get_u32(h + kOffVersion);
  if (version < 1 || version > kIstFormatVersion)
    return Error{who + "unsupported .ist format version " + std::to_string(version) +
                 " (this build reads versions 1 to " + std::to_string(kIstFormatVersion) +
                 "; rebuild the file with this version)"};
  if (get_u32(h + kOffHeaderCrc) != ist_crc32({h, kOffHeaderCrc}))
    return Error{who + "corrupted: header checksum mismatch"};
  if (get_u32(h + kOffHeaderSize) != kIstHeaderSize)
    return Error{who + "corrupted: header size " + std::to_string(get_u32(h + kOffHeaderSize)) +
                 ", expected " + std::to_string(kIstHeaderSize)};
  // version 1 defines no section; version 2 the surface, which a version 2 file holds
  const std::uint32_t flags = get_u32(h + kOffFlags);
  if (version == 1 && flags != 0)
    return Error{who + "corrupted: flags " + std::to_string(flags) + " (format version 1 defines none; expected 0)"};
  if (version == 2 && flags != kIstFlagSurface)
    return Error{who + "corrupted: flags " + std::to_string(flags) + " (format version 2 expects " +
                 std::to_string(kIstFlagSurface) + ", its surface section)"};
  // the reserved bytes are outside the header checksum, so they are checked here
  for (std::size_t i = kOffReserved; i < kIstHeaderSize; ++i)
    if (h[i] != std::byte{0})
      return Error{who + "corrupted: reserved header byte " + std::to_string(i) + " is not zero"};
  const std::uint64_t node_count = get_u32(h + kOffNodes);
  const std::uint64_t leaf_count = get_u32(h + kOffLeaves);
  const std::uint64_t payload = get_u64(h + kOffPayloadBytes);
  if (node_count == 0 || leaf_count == 0 || node_count > 2 * leaf_count ||
      get_u32(h + kOffSphereCount) != leaf_count)
    return Error{who + "corrupted: inconsistent counts (" + std::to_string(node_count) + " nodes, " +
                 std::to_string(leaf_count) + " leaves, " + std::to_string(get_u32(h + kOffSphereCount)) +
                 " spheres)"};
  const std::uint64_t expected = node_count * kNodeBytes + leaf_count * kLeafBytes;
  if (payload != expected)
    return Error{who + "corrupted: payload size " + std::to_string(payload) + " does not match the counts (" +
                 std::to_string(expected) + " bytes)"};
  // compare with the bytes really present before allocating anything
  if (size - kIstHeaderSize < payload)
    return Error{who + "truncated: " + std::to_string(size) + " bytes, the header announces " +
                 std::to_string(kIstHeaderSize + payload)};
  if (flags == 0 && size - kIstHeaderSize > payload)
    return Error{who + "corrupted: " + std::to_string(size - kIstHeaderSize - payload) +
                 " unexpected bytes after the payload"};
  if (get_u32(h + kOffPayloadCrc) != ist_crc32({h + kIstHeaderSize, static_cast<std::size_t>(payload)}))
    return Error{who + "corrupted: payload checksum mismatch"};
  std::optional<TriangleMesh> surface;
  if (flags & kIstFlagSurface) {
    const std::size_t tree_end = kIstHeaderSize + static_cast<std::size_t>(payload);
    auto section = get_surface_section(bytes.subspan(tree_end), size);
    if (!section) return Error{who + section.error().message};
    surface = std::move(*section);
  }

  std::vector<SphereTreeNode> nodes(static_cast<std::size_t>(node_count));
  std::vector<Sphere> leaves(static_cast<std::size_t>(leaf_count));
  const std::byte* p = h + kIstHeaderSize;
  for (SphereTreeNode& n : nodes) {
    n = {get_f32(p + 0),  get_f32(p + 4),  get_f32(p + 8),  get_f32(p + 12),
         get_f32(p + 16), get_i32(p + 20), get_i32(p + 24), get_i32(p + 28)};
    p += kNodeBytes;
  }
  for (Sphere& s : leaves) {
    s = {get_f32(p + 0), get_f32(p + 4), get_f32(p + 8), get_f32(p + 12)};
    p += kLeafBytes;
  }
  const std::uint32_t depth = get_u32(h + kOffDepth);
  const std::uint32_t arity = get_u32(h + kOffArity);
  if (depth > node_count || arity < 2 || arity > static_cast<std::uint32_t>(kMaxSphereTreeArity))
    return Error{who + "corrupted: depth " + std::to_string(depth) + " or arity " + std::to_string(arity) +
                 " out of range"};
  IstAsset asset{
      SphereTree(std::move(nodes), std::move(leaves), static_cast<int>(depth), static_cast<int>(arity)), {}};
  asset.meta.meters_per_unit = get_f64(h + kOffMetersPerUnit);
  asset.meta.source_mesh_hash = get_u64(h + kOffMeshHash);
  asset.meta.coverage = get_f64(h + kOffCoverage);
  asset.meta.mesh_volume = get_f64(h + kOffMeshVolume);
  asset.meta.max_gap = get_f64(h + kOffMaxGap);
  asset.meta.build_seconds = get_f64(h + kOffBuildSeconds);
  asset.surface = std::move(surface);
  if (const Status ok = validate(asset); !ok) return Error{who + ok.error().message};
  return asset;
}

Result<IstAsset> load_ist(const std::filesystem::path& path) {
  const std::string name = path.string();
  // a regular file within the limit, read without blocking on a FIFO or a device
  auto bytes = read_regular_file(path, kMaxFileBytes);
  if (!bytes) return bytes.error();
  // whatever is wrong with what it holds is wrong with the file
  auto asset = load_ist_from_memory(std::as_bytes(std::span<const char>(*bytes)), name);
  if (!asset) return asset.error().classified(ErrorKind::kFile);
  return asset;
}

Status save_ist(const std::filesystem::path& path, const IstAsset& asset) {
  const std::string name = path.string();
  if (const Status ok = validate(asset); !ok)
    return Error{name + ": not saved: " + ok.error().message, ErrorKind::kInvalid};
  const std::vector<std::byte> bytes = encode_ist(asset);
  return write_file_atomically(
      path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

}  // namespace uh::collette
