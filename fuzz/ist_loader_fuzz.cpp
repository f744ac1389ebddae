// libFuzzer target for the .ist loader: any byte string must give an asset that validates or an
// error message, never a crash, an out-of-bounds read or an allocation larger than the input.
//
// Random bytes almost never carry valid CRCs, so when the first byte is odd the harness re-seals
// both checksums of the input (as a hostile writer could) so that the structural checks and the
// tree validation are exercised too.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "uh/collette/ist_file.hpp"

namespace {

void put_u32(std::byte* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::byte>((v >> (8 * i)) & 0xffu);
}

void check(std::span<const std::byte> bytes) {
  const auto r = uh::collette::load_ist_from_memory(bytes, "fuzz.ist");
  if (r) {
    // a loaded asset must be valid and queryable
    if (!uh::collette::validate(r->tree)) std::abort();
    if (r->tree.leaf_count() <= 0 || r->tree.node_count() <= 0) std::abort();
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
    put_u32(sealed.data() + 96, uh::collette::ist_crc32({sealed.data() + uh::collette::kIstHeaderSize, payload}));
    put_u32(sealed.data() + 100, uh::collette::ist_crc32({sealed.data(), 100}));
    check(sealed);
  }
  return 0;
}
