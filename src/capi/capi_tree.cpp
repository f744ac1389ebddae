// The C API's Inner Sphere Trees: load, build (from a file or arrays), save, info, query.

#include <array>
#include <span>
#include <vector>

#include "capi_support.hpp"
#include "uh/collette/distance_query.hpp"
#include "uh/collette/ist_builder.hpp"
#include "uh/collette/volume_query.hpp"

namespace uh::capi {
namespace {

uh_status add_tree(const collette::IstAsset& asset, double meters_per_unit, uh_tree_id* out) {
  // everything the box holds is in metres
  collette::IstAsset metres = collette::ist_asset_in_metres(asset, meters_per_unit);
  auto box = std::make_shared<TreeBox>();
  box->tree = std::make_shared<const collette::SphereTree>(std::move(metres.tree));
  box->meta = metres.meta;
  if (metres.surface) box->surface_bvh = std::make_shared<const collette::MeshInside>(*metres.surface);
  box->surface = std::move(metres.surface);
  const std::uint64_t id = tree_table().insert(std::move(box));
  if (id == 0) return table_full("trees");
  out->bits = id;
  return UH_OK;
}

uh_tree_build_def default_tree_build_def() {
  uh_tree_build_def def{};
  def.struct_size = sizeof def;
  def.spheres = 10000;
  def.meters_per_unit = 1.0;
  return def;
}

// the build options of a def (NULL: the defaults), or a failed status
uh_status build_options(const char* function, const uh_tree_build_def* def, collette::IstBuildOptions& out) {
  uh_tree_build_def d = default_tree_build_def();
  if (def != nullptr)
    if (auto s = read_def(function, "def", def, d); s != UH_OK) return s;
  out = collette::IstBuildOptions{.sphere_count = d.spheres, .meters_per_unit = d.meters_per_unit};
  return UH_OK;
}

// each thread keeps its own query scratch: queries from several threads never share state
collette::VolumeQuery& thread_volume_query() {
  thread_local collette::VolumeQuery query;
  return query;
}
collette::DistanceQuery& thread_distance_query() {
  thread_local collette::DistanceQuery query;
  return query;
}

}  // namespace
}  // namespace uh::capi

using namespace uh;
using namespace uh::capi;

extern "C" {

uh_status uh_tree_build_def_init(uh_tree_build_def* def) {
  return init_def(__func__, def, default_tree_build_def);
}

int32_t uh_tree_is_valid(uh_tree_id tree) { return is_live(tree_table(), tree.bits); }

uh_status uh_tree_load(const char* ist_path, uh_tree_id* out) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    if (ist_path == nullptr) return null_argument(fn, "ist_path");
    if (out == nullptr) return null_argument(fn, "out");
    *out = uh_tree_id{0};
    auto asset = collette::load_ist(ist_path);
    if (!asset) return fail(asset.error(), UH_ERROR_FILE);
    const double scale = asset->meta.meters_per_unit;
    return add_tree(*asset, scale, out);
  });
}

uh_status uh_tree_build(const char* mesh_path, const uh_tree_build_def* def, uh_tree_id* out) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    if (mesh_path == nullptr) return null_argument(fn, "mesh_path");
    if (out == nullptr) return null_argument(fn, "out");
    *out = uh_tree_id{0};
    collette::IstBuildOptions options;
    if (auto s = build_options(fn, def, options); s != UH_OK) return s;
    auto built = collette::build_ist_asset(mesh_path, options);
    if (!built) return fail(built.error(), UH_ERROR_MESH);
    return add_tree(built->asset, options.meters_per_unit, out);
  });
}

uh_status uh_tree_build_from_arrays(const double* vertices, int32_t vertex_count, const int32_t* indices,
                                    int32_t triangle_count, const uh_tree_build_def* def, uh_tree_id* out) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    if (vertices == nullptr) return null_argument(fn, "vertices");
    if (indices == nullptr) return null_argument(fn, "indices");
    if (out == nullptr) return null_argument(fn, "out");
    *out = uh_tree_id{0};
    if (vertex_count < 4 || triangle_count < 4)
      return fail(UH_ERROR_INVALID_ARGUMENT,
                  fmt::format("{}: a closed mesh needs at least 4 vertices and 4 triangles (got {} and {})",
                              fn, vertex_count, triangle_count));
    collette::IstBuildOptions options;
    if (auto s = build_options(fn, def, options); s != UH_OK) return s;
    collette::TriangleMesh mesh;
    mesh.source_name = "mesh arrays";
    mesh.vertices.reserve(static_cast<std::size_t>(vertex_count));
    for (int32_t i = 0; i < vertex_count; ++i) {
      const Vec3 v{vertices[3 * i], vertices[3 * i + 1], vertices[3 * i + 2]};
      if (!is_finite(v))
        return fail(UH_ERROR_INVALID_ARGUMENT, fmt::format("{}: vertex {} is not finite", fn, i));
      mesh.vertices.push_back(v);
    }
    mesh.triangles.reserve(static_cast<std::size_t>(triangle_count));
    for (int32_t t = 0; t < triangle_count; ++t)
      mesh.triangles.push_back({indices[3 * t], indices[3 * t + 1], indices[3 * t + 2]});
    const std::uint64_t hash =
        collette::ist_hash_bytes(std::as_bytes(std::span<const Vec3>(mesh.vertices))) ^
        collette::ist_hash_bytes(std::as_bytes(std::span<const std::array<std::int32_t, 3>>(mesh.triangles)));
    auto valid = collette::validate_mesh(std::move(mesh), options.mesh);
    if (!valid) return fail(valid.error(), UH_ERROR_MESH);
    auto built = collette::build_ist_asset(*valid, hash, options);
    if (!built) return fail(built.error(), UH_ERROR_MESH);
    return add_tree(built->asset, options.meters_per_unit, out);
  });
}

uh_status uh_tree_save(uh_tree_id tree, const char* ist_path) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    if (ist_path == nullptr) return null_argument(fn, "ist_path");
    const auto box = tree_table().find(tree.bits);
    if (!box) return stale(fn, "tree");
    const collette::IstAsset asset{*box->tree, box->meta, box->surface};
    if (auto saved = collette::save_ist(ist_path, asset); !saved) return fail(saved.error(), UH_ERROR_FILE);
    return UH_OK;
  });
}

uh_status uh_tree_get_info(uh_tree_id tree, uh_tree_info* out) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    if (auto s = check_out(fn, "out", out); s != UH_OK) return s;
    const auto box = tree_table().find(tree.bits);
    if (!box) return stale(fn, "tree");
    const collette::SphereTreeNode& root = box->tree->root();
    uh_tree_info info{};
    info.struct_size = sizeof info;
    info.leaf_count = box->tree->leaf_count();
    info.coverage = box->meta.coverage;
    info.mesh_volume = box->meta.mesh_volume;
    info.center[0] = static_cast<double>(root.x);
    info.center[1] = static_cast<double>(root.y);
    info.center[2] = static_cast<double>(root.z);
    info.radius = static_cast<double>(root.radius);
    write_out(info, out);
    return UH_OK;
  });
}

void uh_tree_destroy(uh_tree_id tree) {
  const char* const fn = __func__;
  const uh_status ignored = guarded(fn, [&]() -> uh_status {
    tree_table().remove(tree.bits);
    return UH_OK;
  });
  (void)ignored;
}

uh_status uh_tree_query(uh_tree_id a, uh_tree_id b, const double position[3], const double orientation[4],
                        uh_query_result* out) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    if (auto s = check_out(fn, "out", out); s != UH_OK) return s;
    const auto box_a = tree_table().find(a.bits);
    if (!box_a) return stale(fn, "tree (a)");
    const auto box_b = tree_table().find(b.bits);
    if (!box_b) return stale(fn, "tree (b)");
    auto pose = pose_from_arrays(position, orientation);
    if (!pose) return fail(UH_ERROR_INVALID_ARGUMENT, fmt::format("{}: {}", fn, pose.error().message));
    const auto& r = thread_volume_query().run(*box_a->tree, *box_b->tree, *pose);
    uh_query_result result{};
    result.struct_size = sizeof result;
    result.volume = r.total_volume;
    // each packing fills a share (its coverage) of its mesh (docs/collette-queries.md, "Accuracy")
    const double calibration = box_a->meta.coverage * box_b->meta.coverage;
    result.volume_estimate = calibration > 0.0 ? r.total_volume / calibration : 0.0;
    // the direction of the force the default (gradient) law puts on B
    const Vec3 direction = normalized(-r.volume_gradient);
    result.direction[0] = direction.x;
    result.direction[1] = direction.y;
    result.direction[2] = direction.z;
    result.pair_count = static_cast<int32_t>(r.stats.overlapping_pairs);
    result.distance =
        r.total_volume > 0.0 ? 0.0 : thread_distance_query().run(*box_a->tree, *box_b->tree, *pose).distance;
    write_out(result, out);
    return UH_OK;
  });
}

}  // extern "C"
