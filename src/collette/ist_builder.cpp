#include "uh/collette/ist_builder.hpp"

#include <chrono>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "uh/core/regular_file.hpp"

namespace uh::collette {

Result<std::uint64_t> hash_file(const std::filesystem::path& path) {
  auto bytes = read_regular_file(path, kMaxMeshFileBytes);
  if (!bytes) return bytes.error();
  return ist_hash_bytes(std::as_bytes(std::span<const char>(*bytes)));
}

std::optional<TriangleMesh> ist_surface_of(const TriangleMesh& mesh) {
  if (mesh.report.assumed_open) return std::nullopt;
  return mesh;
}

SphereTree scale_sphere_tree(const SphereTree& tree, double factor) {
  const auto f = static_cast<float>(factor);
  const auto f3 = static_cast<float>(factor * factor * factor);
  std::vector<SphereTreeNode> nodes(tree.nodes().begin(), tree.nodes().end());
  for (auto& n : nodes) {
    n.x *= f;
    n.y *= f;
    n.z *= f;
    n.radius *= f;
    n.volume *= f3;
  }
  std::vector<Sphere> leaves(tree.leaves().begin(), tree.leaves().end());
  for (auto& s : leaves) {
    s.x *= f;
    s.y *= f;
    s.z *= f;
    s.radius *= f;
  }
  return SphereTree(std::move(nodes), std::move(leaves), tree.depth(), tree.arity());
}

IstAsset ist_asset_in_metres(const IstAsset& asset, double meters_per_unit) {
  IstAsset metres{scale_sphere_tree(asset.tree, meters_per_unit), asset.meta, asset.surface};
  metres.meta.mesh_volume *= meters_per_unit * meters_per_unit * meters_per_unit;
  metres.meta.max_gap *= meters_per_unit;
  metres.meta.meters_per_unit = 1.0;
  if (metres.surface)
    for (Vec3& v : metres.surface->vertices) v = v * meters_per_unit;
  return metres;
}

Result<IstBuildResult> build_ist_asset(const std::filesystem::path& mesh_path,
                                       const IstBuildOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  auto mesh = load_mesh(mesh_path, options.mesh);
  if (!mesh) return mesh.error();
  auto hash = hash_file(mesh_path);
  if (!hash) return hash.error();
  auto built = build_ist_asset(*mesh, *hash, options);
  // the build time covers loading too
  if (built)
    built->asset.meta.build_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return built;
}

Result<IstBuildResult> build_ist_asset(const TriangleMesh& mesh, std::uint64_t source_mesh_hash,
                                       const IstBuildOptions& options) {
  const std::string& name = mesh.source_name;
  if (options.sphere_count <= 0)
    return Error{fmt::format("{}: the sphere count must be positive (got {})", name, options.sphere_count),
                 ErrorKind::kInvalid};
  if (!(options.meters_per_unit >= kIstMinMetersPerUnit && options.meters_per_unit <= kIstMaxMetersPerUnit))
    return Error{fmt::format("{}: meters per unit must be between {} and {} (got {})", name,
                             kIstMinMetersPerUnit, kIstMaxMetersPerUnit, options.meters_per_unit),
                 ErrorKind::kInvalid};
  const auto start = std::chrono::steady_clock::now();

  PackingOptions packing_options;
  packing_options.target_sphere_count = options.sphere_count;
  packing_options.voxel_size = options.voxel_size;
  packing_options.max_radius = options.max_radius;
  packing_options.progress = options.progress;
  auto packing = pack_spheres(mesh, packing_options);
  if (!packing) return Error{fmt::format("{}: {}", name, packing.error().message), ErrorKind::kMesh};

  const auto tree_start = std::chrono::steady_clock::now();
  auto tree = build_sphere_tree(packing->spheres, options.tree);
  if (!tree) return Error{fmt::format("{}: sphere tree: {}", name, tree.error().message), ErrorKind::kMesh};
  const auto end = std::chrono::steady_clock::now();

  IstBuildResult result{
      .asset = {std::move(tree).value(), {}}, .mesh = mesh.report, .packing = packing->report};
  result.tree_seconds = std::chrono::duration<double>(end - tree_start).count();
  result.asset.meta = IstMetadata{.meters_per_unit = options.meters_per_unit,
                                  .source_mesh_hash = source_mesh_hash,
                                  .coverage = packing->report.coverage,
                                  .mesh_volume = packing->report.mesh_volume,
                                  .max_gap = packing->report.max_gap,
                                  .build_seconds = std::chrono::duration<double>(end - start).count()};
  result.asset.surface = ist_surface_of(mesh);
  return result;
}

}  // namespace uh::collette
