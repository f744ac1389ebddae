#include "uh/controllers/scene.hpp"

#include "uh/collette/mesh_import.hpp"

namespace uh::controllers {

std::filesystem::path default_cache_dir() { return collette::IstCache::default_dir(); }

Result<ShapeTree> tree_of(const SceneShape& shape, collette::IstCache& cache,
                          const collette::IstCache::Progress& progress) {
  if (shape.tree) return ShapeTree{shape.tree, shape.coverage, shape.surface_gap_m, shape.surface};
  if (!shape.ist.empty()) return cache.ist_tree(shape.ist);
  return cache.mesh_tree(shape.mesh,
                         {.spheres = shape.spheres,
                          .max_radius_m = shape.max_sphere_radius,
                          .meters_per_unit = shape.meters_per_unit},
                         progress);
}

Result<ShapeTree> load_shape_tree(
    const SceneShape& shape, const std::filesystem::path& cache_dir,
    const std::function<void(const std::string& what, double fraction)>& progress) {
  collette::IstCache cache(cache_dir);
  return tree_of(shape, cache, progress);
}

Result<std::shared_ptr<const collette::MeshInside>> load_shape_surface(const SceneShape& shape) {
  if (shape.mesh.empty()) return std::shared_ptr<const collette::MeshInside>{};
  auto mesh = collette::load_mesh(shape.mesh);
  if (!mesh) return mesh.error();
  for (Vec3& v : mesh->vertices) v = v * shape.meters_per_unit;
  return std::make_shared<const collette::MeshInside>(*mesh);
}

Result<soft::SurfaceMesh> load_soft_surface(const SceneShape& shape) {
  if (shape.mesh.empty()) return soft::SurfaceMesh{};
  auto mesh = collette::load_mesh(shape.mesh);
  if (!mesh) return mesh.error();
  for (Vec3& v : mesh->vertices) v = v * shape.meters_per_unit;
  return soft::refine_surface(mesh->vertices, mesh->triangles);
}

}  // namespace uh::controllers
