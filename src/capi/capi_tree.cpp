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

uh_status add_tree(collette::IstAsset asset, double meters_per_unit, uh_tree** out) {
  auto box = std::make_shared<TreeBox>();
  box->tree =
      std::make_shared<const collette::SphereTree>(collette::scale_sphere_tree(asset.tree, meters_per_unit));
  box->meta = asset.meta;
  // everything the box holds is in metres from here on
  box->meta.mesh_volume *= meters_per_unit * meters_per_unit * meters_per_unit;
  box->meta.max_gap *= meters_per_unit;
  box->meta.meters_per_unit = 1.0;
  const std::uintptr_t handle = tree_table().insert(std::move(box));
  if (handle == 0) return fail(UH_ERROR_FAILED, "too many trees are open at once (about a million)");
  *out = as_handle<uh_tree>(handle);
  return UH_OK;
}

Result<collette::IstBuildOptions> build_options(const char* function, const uh_tree_build_def* def) {
  const uh_tree_build_def d = def != nullptr ? *def : uh_default_tree_build_def();
  if (def != nullptr && def->struct_size < sizeof(uh_tree_build_def))
    return Error{fmt::format("{}: def->struct_size is {}, expected at least {}", function, def->struct_size,
                             sizeof(uh_tree_build_def))};
  return collette::IstBuildOptions{.sphere_count = d.spheres, .meters_per_unit = d.meters_per_unit};
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

uh_tree_build_def uh_default_tree_build_def(void) {
  return uh_tree_build_def{
      .struct_size = sizeof(uh_tree_build_def), .spheres = 10000, .meters_per_unit = 1.0};
}

uh_status uh_tree_load(const char* ist_path, uh_tree** out) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    if (ist_path == nullptr) return null_argument(fn, "ist_path");
    if (out == nullptr) return null_argument(fn, "out");
    *out = nullptr;
    auto asset = collette::load_ist(ist_path);
    if (!asset) return fail(UH_ERROR_FAILED, asset.error().message);
    const double scale = asset->meta.meters_per_unit;
    return add_tree(std::move(asset).value(), scale, out);
  });
}

uh_status uh_tree_build(const char* mesh_path, const uh_tree_build_def* def, uh_tree** out) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    if (mesh_path == nullptr) return null_argument(fn, "mesh_path");
    if (out == nullptr) return null_argument(fn, "out");
    *out = nullptr;
    auto options = build_options(fn, def);
    if (!options) return fail(UH_ERROR_INVALID_ARGUMENT, options.error().message);
    auto built = collette::build_ist_asset(mesh_path, *options);
    if (!built) return fail(UH_ERROR_FAILED, built.error().message);
    return add_tree(std::move(built->asset), options->meters_per_unit, out);
  });
}

uh_status uh_tree_build_from_arrays(const double* vertices, int32_t vertex_count, const int32_t* indices,
                                    int32_t triangle_count, const uh_tree_build_def* def, uh_tree** out) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    if (vertices == nullptr) return null_argument(fn, "vertices");
    if (indices == nullptr) return null_argument(fn, "indices");
    if (out == nullptr) return null_argument(fn, "out");
    *out = nullptr;
    if (vertex_count < 4 || triangle_count < 4)
      return fail(UH_ERROR_INVALID_ARGUMENT,
                  fmt::format("{}: a closed mesh needs at least 4 vertices and 4 triangles (got {} and {})",
                              fn, vertex_count, triangle_count));
    auto options = build_options(fn, def);
    if (!options) return fail(UH_ERROR_INVALID_ARGUMENT, options.error().message);
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
    auto valid = collette::validate_mesh(std::move(mesh), options->mesh);
    if (!valid) return fail(UH_ERROR_FAILED, valid.error().message);
    auto built = collette::build_ist_asset(*valid, hash, *options);
    if (!built) return fail(UH_ERROR_FAILED, built.error().message);
    return add_tree(std::move(built->asset), options->meters_per_unit, out);
  });
}

uh_status uh_tree_save(const uh_tree* tree, const char* ist_path) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    if (ist_path == nullptr) return null_argument(fn, "ist_path");
    const auto box = tree_table().find(handle_value(tree));
    if (!box) return stale(fn, "tree");
    const collette::IstAsset asset{*box->tree, box->meta};
    if (auto saved = collette::save_ist(ist_path, asset); !saved)
      return fail(UH_ERROR_FAILED, saved.error().message);
    return UH_OK;
  });
}

uh_status uh_tree_get_info(const uh_tree* tree, uh_tree_info* out) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    if (auto s = check_struct(fn, "out", out); s != UH_OK) return s;
    const auto box = tree_table().find(handle_value(tree));
    if (!box) return stale(fn, "tree");
    const collette::SphereTreeNode& root = box->tree->root();
    out->leaf_count = box->tree->leaf_count();
    out->coverage = box->meta.coverage;
    out->mesh_volume = box->meta.mesh_volume;
    out->center[0] = static_cast<double>(root.x);
    out->center[1] = static_cast<double>(root.y);
    out->center[2] = static_cast<double>(root.z);
    out->radius = static_cast<double>(root.radius);
    return UH_OK;
  });
}

void uh_tree_free(uh_tree* tree) {
  const char* const fn = __func__;
  const uh_status ignored = guarded(fn, [&]() -> uh_status {
    tree_table().remove(handle_value(tree));
    return UH_OK;
  });
  (void)ignored;
}

uh_status uh_tree_query(const uh_tree* a, const uh_tree* b, const double position[3],
                        const double orientation[4], uh_query_result* out) {
  const char* const fn = __func__;
  return guarded(fn, [&]() -> uh_status {
    if (auto s = check_struct(fn, "out", out); s != UH_OK) return s;
    const auto box_a = tree_table().find(handle_value(a));
    if (!box_a) return stale(fn, "tree (a)");
    const auto box_b = tree_table().find(handle_value(b));
    if (!box_b) return stale(fn, "tree (b)");
    auto pose = pose_from_arrays(position, orientation);
    if (!pose) return fail(UH_ERROR_INVALID_ARGUMENT, fmt::format("{}: {}", fn, pose.error().message));
    const auto& r = thread_volume_query().run(*box_a->tree, *box_b->tree, *pose);
    out->volume = r.total_volume;
    // each packing fills a share (its coverage) of its mesh (docs/collette-queries.md, "Accuracy")
    const double calibration = box_a->meta.coverage * box_b->meta.coverage;
    out->volume_estimate = calibration > 0.0 ? r.total_volume / calibration : 0.0;
    // the direction of the force the default (gradient) law puts on B
    const Vec3 direction = normalized(-r.volume_gradient);
    out->direction[0] = direction.x;
    out->direction[1] = direction.y;
    out->direction[2] = direction.z;
    out->pair_count = static_cast<int32_t>(r.stats.overlapping_pairs);
    out->distance =
        r.total_volume > 0.0 ? 0.0 : thread_distance_query().run(*box_a->tree, *box_b->tree, *pose).distance;
    return UH_OK;
  });
}

}  // extern "C"
