#include "uh/collette/ist_cache.hpp"

#include <cstdlib>
#include <system_error>

#include <fmt/format.h>

#include "uh/collette/ist_builder.hpp"
#include "uh/collette/ist_file.hpp"
#include "uh/collette/sphere_tree_builder.hpp"

namespace uh::collette {
namespace {

CachedTree in_metres(const IstAsset& asset, double meters_per_unit) {
  IstAsset metres = ist_asset_in_metres(asset, meters_per_unit);
  CachedTree tree{std::make_shared<const SphereTree>(std::move(metres.tree)), metres.meta.coverage,
                  metres.meta.max_gap};
  if (metres.surface) tree.surface = std::make_shared<const MeshInside>(*metres.surface);
  return tree;
}

// A cache file of an older format keeps its spheres and gains the surface they were packed in:
// the mesh file's (the file's hash is the one packed), read again rather than packed again, and
// written back for the next run (a cache folder that cannot be written keeps working without).
Status add_mesh_surface(const std::filesystem::path& mesh, const std::filesystem::path& cached, IstAsset& asset) {
  auto surface = load_mesh(mesh);
  if (!surface) return surface.error();
  asset.surface = ist_surface_of(*surface);
  static_cast<void>(save_ist(cached, asset));
  return Ok{};
}

}  // namespace

IstCache::IstCache(std::filesystem::path dir) : dir_(dir.empty() ? default_dir() : std::move(dir)) {}

std::filesystem::path IstCache::default_dir() {
  if (const char* dir = std::getenv("UH_CACHE_DIR"); dir != nullptr && *dir != '\0') return dir;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg != nullptr && *xdg != '\0')
    return std::filesystem::path(xdg) / "unrealhaptics";
  // Windows' per-user cache folder (set there, never on Linux)
  if (const char* local = std::getenv("LOCALAPPDATA"); local != nullptr && *local != '\0')
    return std::filesystem::path(local) / "unrealhaptics" / "cache";
  if (const char* home = std::getenv("HOME"); home != nullptr && *home != '\0')
    return std::filesystem::path(home) / ".cache" / "unrealhaptics";
  return std::filesystem::temp_directory_path() / "unrealhaptics-cache";
}

Result<CachedTree> IstCache::ist_tree(const std::filesystem::path& ist) {
  const Key key{"ist:" + ist.string(), 0, 0.0, 0.0};
  if (const auto it = loaded_.find(key); it != loaded_.end()) return it->second;
  auto asset = load_ist(ist);
  if (!asset) return asset.error();
  const CachedTree tree = in_metres(*asset, asset->meta.meters_per_unit);
  loaded_.emplace(key, tree);
  return tree;
}

Result<CachedTree> IstCache::mesh_tree(const std::filesystem::path& mesh, const MeshPacking& packing,
                                       const Progress& progress) {
  const Key key{"mesh:" + mesh.string(), packing.spheres, packing.max_radius_m, packing.meters_per_unit};
  if (const auto it = loaded_.find(key); it != loaded_.end()) return it->second;
  auto hash = hash_file(mesh);
  if (!hash) return hash.error();
  std::error_code ec;
  std::filesystem::create_directories(dir_, ec);
  if (ec)
    return Error{fmt::format("{}: cannot create the cache folder: {}", dir_.string(), ec.message()), ErrorKind::kFile};
  // keyed by everything the packing depends on (the radius bound in mesh units, shortest exact
  // form) and by the tree builder's version (a cache of an older builder's tree is rebuilt)
  const double max_radius = packing.max_radius_m / packing.meters_per_unit;
  const std::string bound = max_radius > 0.0 ? fmt::format("-r{}", max_radius) : std::string();
  const std::filesystem::path cached =
      dir_ / fmt::format("{}-{:016x}-{}{}-t{}.ist", mesh.stem().string(), *hash, packing.spheres, bound,
                         kSphereTreeBuilderVersion);
  IstAsset asset;
  auto loaded = load_ist(cached);
  if (loaded && loaded->meta.source_mesh_hash == *hash) {
    asset = std::move(loaded).value();
    if (!asset.surface)
      if (Status upgraded = add_mesh_surface(mesh, cached, asset); !upgraded) return upgraded.error();
  } else {
    // absent, unreadable or stale: build it again (only the cache file is replaced)
    const std::string what = fmt::format("packing {} ({} spheres)", mesh.filename().string(), packing.spheres);
    IstBuildOptions options{
        .sphere_count = packing.spheres, .max_radius = max_radius, .meters_per_unit = packing.meters_per_unit};
    if (progress) options.progress = [&](double f) { progress(what, f); };
    auto built = build_ist_asset(mesh, options);
    if (!built) return built.error();
    if (auto saved = save_ist(cached, built->asset); !saved) return saved.error();
    asset = std::move(built->asset);
  }
  const CachedTree tree = in_metres(asset, packing.meters_per_unit);
  loaded_.emplace(key, tree);
  return tree;
}

}  // namespace uh::collette
