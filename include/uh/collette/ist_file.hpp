#pragma once
/// \file
/// The .ist asset file: a packed and built Inner Sphere Tree with the facts about its packing.
///
/// Versioned little-endian binary (byte layout in docs/collette-queries.md): a 128-byte header
/// (magic, format version, counts, units, a hash of the source mesh, packing report, payload size,
/// CRC-32 of the payload and of the header), then the node array (32 bytes a node) and the leaf
/// spheres (16 bytes each), then (version 2) the surface the spheres were packed in. Loaders check
/// every count against the real size before allocating and validate() the asset (tree, metadata
/// and surface), so a hostile file gives an error message, never a crash and never a meaningless
/// asset.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "uh/collette/sphere_tree.hpp"
#include "uh/collette/triangle_mesh.hpp"
#include "uh/core/result.hpp"

namespace uh::collette {

/// The newest format version: load_ist() reads versions 1 (tree and metadata) and 2 (version 1 and
/// the sections its flags announce). save_ist() writes the oldest that holds the asset: version 1
/// without a surface (so older builds read it), version 2 with one.
inline constexpr std::uint32_t kIstFormatVersion = 2;
/// Header flag of version 2: a surface section follows the leaves. Version 2 defines no other
/// section and requires this one (a file without it is version 1).
inline constexpr std::uint32_t kIstFlagSurface = 1;
/// Most triangles a surface section holds (20 times the Stanford dragon's); its vertices are at
/// most as many (a closed surface has V <= T).
inline constexpr std::uint32_t kIstMaxSurfaceTriangles = std::uint32_t{1} << 24;
/// Size of the fixed header [bytes].
inline constexpr std::size_t kIstHeaderSize = 128;

/// Facts stored next to the tree: units, provenance and the packing report.
/// validate(const IstAsset&) states what each field must hold.
struct IstMetadata {
  double meters_per_unit =
      1.0;  ///< length of one mesh unit [m], in [kIstMinMetersPerUnit, kIstMaxMetersPerUnit]
  std::uint64_t source_mesh_hash =
      0;                       ///< hash of the source mesh (e.g. ist_hash_bytes of the file), 0 if unknown
  double coverage = 0.0;       ///< sphere volume / mesh volume, in (0, 1]
  double mesh_volume = 0.0;    ///< volume of the closed mesh [length^3], > 0
  double max_gap = 0.0;        ///< largest distance from the surface to the spheres [length], >= 0
  double build_seconds = 0.0;  ///< time the packing and tree build took [s], >= 0
};

/// Accepted range of IstMetadata::meters_per_unit [m]: a nanometre to a million kilometres.
inline constexpr double kIstMinMetersPerUnit = 1e-9;
inline constexpr double kIstMaxMetersPerUnit = 1e9;
/// Largest relative difference accepted between IstMetadata::coverage and the tree's sphere
/// volume / mesh_volume (the tree sums float volumes; the packing sums doubles).
inline constexpr double kIstCoverageTolerance = 1e-3;

/// A loaded or to-be-saved asset. The sphere count, node count and depth come from the tree.
struct IstAsset {
  SphereTree tree;
  IstMetadata meta;
  /// The closed surface the spheres were packed in, in the tree's frame and units, wound outward
  /// as validate_mesh() leaves it (the 6-DOF proxy rests on it rather than on the spheres' grain);
  /// none in a version 1 file and for a mesh packed open (its holes capped only for the packing).
  std::optional<TriangleMesh> surface{};
};

/// Checks that `asset` means what the format says, beyond what validate(const SphereTree&)
/// checks: no node has more children than the tree's arity; the leaf spheres do not overlap
/// (they are a packing: the volume query and the coverage assume it; overlaps up to 1e-5 of the
/// root radius are float rounding and accepted); every leaf radius is at least 1e-9 of its
/// centre's distance from the origin; meters_per_unit finite and in
/// [kIstMinMetersPerUnit, kIstMaxMetersPerUnit]; mesh_volume finite, positive and at least the
/// sphere volume; coverage in (0, 1] and equal to sphere volume / mesh_volume within
/// kIstCoverageTolerance; max_gap and build_seconds finite and >= 0; a surface, when there is one,
/// closed, 2-manifold and wound outward as stored (validate_mesh() with no welding and no repair
/// drops no vertex and turns no triangle), enclosing mesh_volume (relative 1e-6), with every leaf sphere inside
/// its bounding box. The message names the first broken field ("invalid tree: ...", "invalid
/// metadata: <field> ..." or "invalid surface section: ..."). Not real-time safe (allocates);
/// any thread.
Status validate(const IstAsset& asset);

/// Writes `asset` to `path` atomically: to a temporary file in the same directory, flushed to
/// disk, then renamed over `path`, so a failure never leaves a half-written or clobbered file.
/// Fails (message names the file) when validate(asset) fails or the file cannot be written.
/// Not real-time safe; any thread.
Status save_ist(const std::filesystem::path& path, const IstAsset& asset);

/// Reads and checks a .ist file. The error names the file and says what is wrong: missing,
/// truncated (the header, the tree or the surface section), not a .ist file (magic), unsupported
/// format version, corrupted (checksums, counts, flags or reserved bytes), or a tree, metadata or
/// surface that fails validate(const IstAsset&), naming the field. Whatever loads re-encodes to the same bytes. Not real-time safe; any thread.
Result<IstAsset> load_ist(const std::filesystem::path& path);

/// Decodes a .ist image from memory (the fuzz target's entry point). `name` prefixes messages.
Result<IstAsset> load_ist_from_memory(std::span<const std::byte> bytes, std::string_view name = "<memory>");

/// Encodes `asset` (not validated) into a .ist image: version 1, or 2 with its surface section.
std::vector<std::byte> encode_ist(const IstAsset& asset);

/// CRC-32 (IEEE 802.3, as zlib's crc32) of `bytes`.
std::uint32_t ist_crc32(std::span<const std::byte> bytes);

/// 64-bit FNV-1a hash of `bytes`, for IstMetadata::source_mesh_hash.
std::uint64_t ist_hash_bytes(std::span<const std::byte> bytes);

}  // namespace uh::collette
