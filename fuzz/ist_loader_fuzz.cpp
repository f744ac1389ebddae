// libFuzzer target for the .ist loader: any byte string must give an asset that means what the
// format says, or an error message; never a crash, an out-of-bounds read or an allocation larger
// than the input.
//
// Random bytes almost never carry valid CRCs, so when the first byte is odd the harness re-seals
// both checksums of the input (as a hostile writer could) so that the structural and semantic
// checks are exercised too. The oracle for anything that loads: the tree and the asset validate,
// the asset re-encodes to exactly the input bytes (no byte is ignored), and a brute-force check
// written independently of the loader's grid finds no overlapping leaves, no leaf outside the
// root and no metadata out of range.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
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
    const std::size_t payload = size - uh::collette::kIstHeaderSize;
    put_u32(sealed.data() + 96,
            uh::collette::ist_crc32({sealed.data() + uh::collette::kIstHeaderSize, payload}));
    put_u32(sealed.data() + 100, uh::collette::ist_crc32({sealed.data(), 100}));
    check(sealed);
  }
  return 0;
}
