// libFuzzer target for the .ist loader: any byte string must give an asset that means what the
// format says, or an error message; never a crash, an out-of-bounds read or an allocation larger
// than the input.
//
// Random bytes almost never carry valid CRCs, so when the first byte is odd the harness re-seals
// the checksums of the input (header, tree payload and, after it, the surface section's closing
// one, as a hostile writer could) so that the structural and semantic checks are exercised too.
// The oracle for anything that loads: the tree and the asset validate, the asset re-encodes to
// exactly the input bytes (no byte is ignored), and a brute-force check written independently of
// the loader's grid and of the mesh validator finds no overlapping leaves, no leaf outside the root,
// no metadata out of range, and a surface (when there is one) whose every directed edge is met once
// by its reverse (closed and consistently wound), enclosing the metadata's volume, around the leaves.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <utility>
#include <vector>

#include "uh/collette/ist_file.hpp"

namespace {

void put_u32(std::byte* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::byte>((v >> (8 * i)) & 0xffu);
}

// all pairs for small trees: the loader's check uses a grid per radius class
bool brute_force_meaningful(const uh::collette::IstAsset& a) {
  const auto& m = a.meta;
  if (!(std::isfinite(m.meters_per_unit) && m.meters_per_unit > 0.0)) return false;
  if (!(std::isfinite(m.mesh_volume) && m.mesh_volume > 0.0)) return false;
  if (!(m.coverage > 0.0 && m.coverage <= 1.0)) return false;
  if (!(std::isfinite(m.max_gap) && m.max_gap >= 0.0 && std::isfinite(m.build_seconds) &&
        m.build_seconds >= 0.0))
    return false;
  const auto leaves = a.tree.leaves();
  const auto& root = a.tree.root();
  const double tol = 1e-5 * static_cast<double>(root.radius);
  auto dist = [](const auto& a, const auto& b) {
    const double dx = static_cast<double>(a.x) - static_cast<double>(b.x);
    const double dy = static_cast<double>(a.y) - static_cast<double>(b.y);
    const double dz = static_cast<double>(a.z) - static_cast<double>(b.z);
    return std::sqrt(dx * dx + dy * dy + dz * dz);
  };
  if (leaves.size() > 600) return true;
  for (std::size_t i = 0; i < leaves.size(); ++i) {
    const auto& s = leaves[i];
    if (!(std::isfinite(s.radius) && s.radius > 0.f)) return false;
    if (dist(s, root) + static_cast<double>(s.radius) > static_cast<double>(root.radius) + tol) return false;
    for (std::size_t j = i + 1; j < leaves.size(); ++j) {
      const auto& t = leaves[j];
      if (static_cast<double>(s.radius) + static_cast<double>(t.radius) - dist(s, t) > tol) return false;
    }
  }
  return true;
}

// a small surface by brute force: indices in range, finite corners, every directed edge once with
// its reverse once, a positive volume equal to the metadata's, the leaves' centres inside its box
bool brute_force_surface(const uh::collette::IstAsset& a) {
  const auto& m = *a.surface;
  if (m.triangles.size() > 600) return true;
  for (const auto& v : m.vertices)
    if (!(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z))) return false;
  std::vector<std::pair<std::int32_t, std::int32_t>> edges;
  double volume = 0.0;
  for (const auto& t : m.triangles) {
    for (int k = 0; k < 3; ++k) {
      const std::int32_t i = t[static_cast<std::size_t>(k)];
      if (i < 0 || static_cast<std::size_t>(i) >= m.vertices.size()) return false;
      edges.emplace_back(i, t[static_cast<std::size_t>((k + 1) % 3)]);
    }
    const auto &p = m.vertices[static_cast<std::size_t>(t[0])], &q = m.vertices[static_cast<std::size_t>(t[1])],
               &r = m.vertices[static_cast<std::size_t>(t[2])];
    volume += (p.x * (q.y * r.z - q.z * r.y) - p.y * (q.x * r.z - q.z * r.x) + p.z * (q.x * r.y - q.y * r.x)) / 6.0;
  }
  for (const auto& [i, j] : edges) {
    if (std::count(edges.begin(), edges.end(), std::pair{i, j}) != 1) return false;
    if (std::count(edges.begin(), edges.end(), std::pair{j, i}) != 1) return false;
  }
  if (!(volume > 0.0 && std::abs(volume - a.meta.mesh_volume) <= 1e-5 * volume)) return false;
  // a leaf's centre with every corner on one side of it along an axis lies outside the surface
  for (const auto& s : a.tree.leaves()) {
    const double c[3] = {static_cast<double>(s.x), static_cast<double>(s.y), static_cast<double>(s.z)};
    for (int axis = 0; axis < 3; ++axis) {
      bool all_above = true, all_below = true;
      for (const auto& v : m.vertices) {
        const double x = axis == 0 ? v.x : axis == 1 ? v.y : v.z;
        all_above = all_above && x > c[axis];
        all_below = all_below && x < c[axis];
      }
      if (all_above || all_below) return false;
    }
  }
  return true;
}

void check(std::span<const std::byte> bytes) {
  const auto r = uh::collette::load_ist_from_memory(bytes, "fuzz.ist");
  if (r) {
    if (!uh::collette::validate(r->tree)) std::abort();
    if (!uh::collette::validate(*r)) std::abort();
    if (r->tree.leaf_count() <= 0 || r->tree.node_count() <= 0) std::abort();
    const std::vector<std::byte> again = uh::collette::encode_ist(*r);
    if (again.size() != bytes.size() || std::memcmp(again.data(), bytes.data(), bytes.size()) != 0)
      std::abort();
    if (!brute_force_meaningful(*r)) std::abort();
    if (r->surface && !brute_force_surface(*r)) std::abort();
  } else if (r.error().message.empty()) {
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto* bytes = reinterpret_cast<const std::byte*>(data);
  check({bytes, size});
  if (size >= uh::collette::kIstHeaderSize && (data[0] & 1u)) {
    std::vector<std::byte> sealed(bytes, bytes + size);
    sealed[0] = std::byte{'U'};
    // the tree payload as its header announces it (at most what is there); the rest is the surface
    // section, whose last 4 bytes are its checksum
    const std::size_t rest = size - uh::collette::kIstHeaderSize;
    std::uint64_t payload = 0;
    for (std::size_t i = 0; i < 8; ++i) payload |= static_cast<std::uint64_t>(data[88 + i]) << (8 * i);
    payload = std::min<std::uint64_t>(payload, rest);
    std::byte* tree = sealed.data() + uh::collette::kIstHeaderSize;
    put_u32(sealed.data() + 96, uh::collette::ist_crc32({tree, static_cast<std::size_t>(payload)}));
    if (rest - payload >= 12) {
      std::byte* section = tree + payload;
      const std::size_t checked = rest - static_cast<std::size_t>(payload) - 4;
      put_u32(section + checked, uh::collette::ist_crc32({section, checked}));
    }
    put_u32(sealed.data() + 100, uh::collette::ist_crc32({sealed.data(), 100}));
    check(sealed);
  }
  return 0;
}
