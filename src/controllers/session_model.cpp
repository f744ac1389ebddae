#include "uh/controllers/session_model.hpp"

#include <map>
#include <utility>

#include <fmt/format.h>

#include "uh/scene/validate.hpp"

namespace uh::controllers {
namespace {

// A shape's surface: the one its .ist holds (a .ist file's, a packed mesh's cache file's), else its
// mesh file's (a tree given beside its mesh), one per (file, scale) shared by the objects that
// repeat it.
class SurfaceLoader {
 public:
  SurfaceLoader(bool any, bool beside_given_tree) : any_(any), beside_given_tree_(beside_given_tree) {}

  Result<std::shared_ptr<const collette::MeshInside>> load(const SceneShape& shape, const ShapeTree& tree) {
    if (!any_) return std::shared_ptr<const collette::MeshInside>{};
    if (tree.surface) return tree.surface;
    if (shape.mesh.empty() || (shape.tree && !beside_given_tree_)) return std::shared_ptr<const collette::MeshInside>{};
    const auto key = std::make_pair(shape.mesh.string(), shape.meters_per_unit);
    if (const auto it = loaded_.find(key); it != loaded_.end()) return it->second;
    auto surface = load_shape_surface(shape);
    if (surface) loaded_.emplace(key, *surface);
    return surface;
  }

 private:
  bool any_;
  bool beside_given_tree_;
  std::map<std::pair<std::string, double>, std::shared_ptr<const collette::MeshInside>> loaded_;
};

Error named(const Scene& scene, const std::string& part, const Error& error) {
  return Error{fmt::format("{}: {}: {}", scene.source, part, error.message), error.kind};
}

soft::SoftBodyParams soft_params(const scene::SceneDeformable& d) {
  soft::SoftBodyParams params;
  params.material = {.young_modulus_pa = d.young_modulus_pa,
                     .poisson_ratio = d.poisson_ratio,
                     .density_kg_m3 = d.density_kg_m3,
                     .mass_damping_per_s = 0.0,
                     .stiffness_damping_s = d.damping};
  params.target_tetrahedra = static_cast<int>(d.tetrahedra);
  if (d.fixed_box) {
    const auto eigen = [](const Vec3& v) { return Eigen::Vector3d(v.x, v.y, v.z); };
    params.fixed = soft::Box{.min = eigen(d.fixed_box->min), .max = eigen(d.fixed_box->max)};
  }
  return params;
}

// a deformable object's lattice around its packing, inside its mesh surface (loaded here when
// the model keeps no surface)
Result<std::shared_ptr<const soft::SoftBodyModel>> compile_soft_body(const SceneObject& object, const ShapeTree& tree,
                                                                     std::shared_ptr<const collette::MeshInside> surface,
                                                                     const CompileOptions& options) {
  if (!object.deformable) return std::shared_ptr<const soft::SoftBodyModel>{};
  if (!surface) {
    auto loaded = load_shape_surface(object.shape);
    if (!loaded) return loaded.error();
    surface = *loaded;
  }
  const std::string stage = fmt::format("meshing the volume of '{}'", object.name);
  if (options.progress) options.progress(stage, 0.0);
  const auto inside = [&](const Eigen::Vector3d& p) { return surface->contains({p.x(), p.y(), p.z()}); };
  auto drawn = load_soft_surface(object.shape);
  if (!drawn) return drawn.error();
  soft::SoftBodyParams params = soft_params(*object.deformable);
  params.surface = std::move(*drawn);
  auto body = soft::build_soft_body(inside, tree.tree->leaves(), params);
  if (!body) return body.error();
  if (options.progress) options.progress(stage, 1.0);
  return std::make_shared<const soft::SoftBodyModel>(std::move(*body));
}

Status compile_objects(collette::IstCache& cache, const CompileOptions& options, SessionModel& model) {
  const Scene& scene = model.scene;
  SurfaceLoader surfaces(options.surfaces, options.surface_beside_given_tree);
  for (SceneObject& object : model.scene.objects) {
    const std::string part = fmt::format("object '{}'", object.name);
    auto tree = tree_of(object.shape, cache, options.progress);
    if (!tree) return named(scene, part, tree.error());
    auto surface = surfaces.load(object.shape, *tree);
    if (!surface) return named(scene, part, surface.error());
    auto body = compile_soft_body(object, *tree, *surface, options);
    if (!body) return named(scene, part, body.error());
    model.objects.push_back({.tree = tree->tree,
                             .coverage = tree->coverage,
                             .surface = *surface,
                             .surface_gap_m = tree->max_gap_m,
                             .soft = *body});
    object.shape.tree = tree->tree;
    object.shape.coverage = tree->coverage;
  }
  return Ok{};
}

Status compile_tools(collette::IstCache& cache, const CompileOptions& options, SessionModel& model) {
  const Scene& scene = model.scene;
  for (SceneTool& tool : model.scene.tools) {
    auto tree = tree_of(tool.shape, cache, options.progress);
    if (!tree) return named(scene, fmt::format("tool '{}'", tool.name), tree.error());
    // a tool's surface is not used: the proxy rests the tool's spheres on the objects' surfaces
    model.tools.push_back({.tree = tree->tree, .coverage = tree->coverage, .surface = nullptr, .surface_gap_m = 0.0, .soft = nullptr});
    tool.shape.tree = tree->tree;
    tool.shape.coverage = tree->coverage;
    auto& row = model.materials.emplace_back();
    for (const SceneObject& object : scene.objects)
      row.push_back(forcecomp::combine_materials(object.material, tool.material, tool.force));
  }
  return Ok{};
}

}  // namespace

Result<std::shared_ptr<const SessionModel>> compile(const Scene& scene, collette::IstCache& cache,
                                                    const CompileOptions& options) {
  if (Status valid = uh::scene::validate(scene); !valid)
    return Error{fmt::format("{}: {}", scene.source, valid.error().message), ErrorKind::kInvalid};
  auto model = std::make_shared<SessionModel>();
  model->scene = scene;
  model->scene.force.coupling.period_s = 1.0 / scene.haptic_hz;
  if (Status s = compile_objects(cache, options, *model); !s) return s.error();
  if (Status s = compile_tools(cache, options, *model); !s) return s.error();
  return std::shared_ptr<const SessionModel>(std::move(model));
}

}  // namespace uh::controllers
