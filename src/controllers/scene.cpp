#include "uh/controllers/scene.hpp"

#include <cstdlib>

#include <fmt/format.h>

#include "uh/collette/ist_builder.hpp"
#include "uh/collette/ist_file.hpp"
#include "uh/collette/mesh_import.hpp"
#include "uh/collette/sphere_tree_builder.hpp"

namespace uh::controllers {

std::filesystem::path default_cache_dir() {
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


Result<ShapeTree> load_shape_tree(
    const SceneShape& shape, const std::filesystem::path& cache_dir,
    const std::function<void(const std::string& what, double fraction)>& progress) {
  if (shape.tree) return ShapeTree{shape.tree, shape.coverage};
  collette::IstAsset asset;
  if (!shape.ist.empty()) {
    auto loaded = collette::load_ist(shape.ist);
    if (!loaded) return loaded.error();
    asset = std::move(loaded).value();
  } else {
    auto hash = collette::hash_file(shape.mesh);
    if (!hash) return hash.error();
    std::error_code ec;
    std::filesystem::create_directories(cache_dir, ec);
    if (ec)
      return Error{fmt::format("{}: cannot create the cache folder: {}", cache_dir.string(), ec.message()),
                   ErrorKind::kFile};
    // keyed by everything the packing depends on (the radius bound in mesh units, shortest exact
    // form) and by the tree builder's version (a cache of an older builder's tree is rebuilt)
    const double max_radius = shape.max_sphere_radius / shape.meters_per_unit;
    const std::string bound = max_radius > 0.0 ? fmt::format("-r{}", max_radius) : std::string();
    const std::filesystem::path cached =
        cache_dir / fmt::format("{}-{:016x}-{}{}-t{}.ist", shape.mesh.stem().string(), *hash, shape.spheres,
                                bound, collette::kSphereTreeBuilderVersion);
    auto loaded = collette::load_ist(cached);
    if (loaded && loaded->meta.source_mesh_hash == *hash) {
      asset = std::move(loaded).value();
    } else {
      // absent, unreadable or stale: build it again (only the cache file is replaced)
      const std::string what = fmt::format("packing {} ({} spheres)", shape.mesh.filename().string(), shape.spheres);
      collette::IstBuildOptions options{
          .sphere_count = shape.spheres, .max_radius = max_radius, .meters_per_unit = shape.meters_per_unit};
      if (progress) options.progress = [&](double f) { progress(what, f); };
      auto built = collette::build_ist_asset(shape.mesh, options);
      if (!built) return built.error();
      if (auto saved = collette::save_ist(cached, built->asset); !saved) return saved.error();
      asset = std::move(built->asset);
    }
  }
  const double scale = shape.ist.empty() ? shape.meters_per_unit : asset.meta.meters_per_unit;
  return ShapeTree{
      std::make_shared<const collette::SphereTree>(collette::scale_sphere_tree(asset.tree, scale)),
      asset.meta.coverage};
}

Result<std::shared_ptr<const collette::MeshInside>> load_shape_surface(const SceneShape& shape) {
  if (shape.mesh.empty() || shape.tree) return std::shared_ptr<const collette::MeshInside>{};
  auto mesh = collette::load_mesh(shape.mesh);
  if (!mesh) return mesh.error();
  for (Vec3& v : mesh->vertices) v = v * shape.meters_per_unit;
  return std::make_shared<const collette::MeshInside>(*mesh);
}

}  // namespace uh::controllers
