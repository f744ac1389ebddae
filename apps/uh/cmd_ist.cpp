// uh ist build | info | preview
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "progress_bar.hpp"
#include "uh/collette/ist_builder.hpp"
#include "uh/collette/ist_file.hpp"
#include "uh/collette/packing_preview.hpp"

namespace uh::cli {
namespace {

struct IstBuildArgs {
  std::string mesh;
  std::string out;
  std::int64_t spheres = 10000;
  double voxel = 0.0;
  double max_radius = 0.0;
  double meters_per_unit = 1.0;
  std::string preview;
  bool json = false;
  bool allow_open = false;
};

struct IstInfoArgs {
  std::string file;
  bool json = false;
};

struct IstPreviewArgs {
  std::string file;
  std::string out;
  bool section = false;
  int width = 800;
  int height = 800;
};

std::string mesh_assumptions(const collette::MeshReport& r) {
  std::string text;
  if (r.assumed_open)
    text += fmt::format(
        "accepted an open mesh ({} boundary edges): holes capped, inside tests use the winding number; ",
        r.boundary_edges);
  if (!text.empty()) text.resize(text.size() - 2);
  return text;
}

std::string mesh_repairs(const collette::MeshReport& r) {
  std::string text;
  if (r.degenerate_faces > 0) text += fmt::format("dropped {} degenerate faces; ", r.degenerate_faces);
  if (r.duplicate_faces > 0) text += fmt::format("dropped {} duplicate faces; ", r.duplicate_faces);
  if (r.winding_flipped) text += "inverted winding fixed (all triangles flipped); ";
  if (!text.empty()) text.resize(text.size() - 2);
  return text;
}

// The mesh as `ist build` accepts it: repaired, and open only with --allow-open. It is loaded as
// if open meshes were allowed, so that this command, not the library, decides and can name its
// own option.
Result<collette::TriangleMesh> load_build_mesh(const IstBuildArgs& args) {
  const collette::MeshLoadOptions defaults{};
  collette::MeshLoadOptions options{.allow_open = true, .max_open_boundary_edges = INT64_MAX, .repair = true};
  auto mesh = collette::load_mesh(args.mesh, options);
  if (!mesh) return mesh;
  const collette::MeshReport& r = mesh->report;
  if (!r.assumed_open) return mesh;
  const std::string repaired = r.repaired
                                   ? fmt::format(" after dropping {} degenerate and {} duplicate faces",
                                                 r.degenerate_faces, r.duplicate_faces)
                                   : std::string();
  const std::string what = fmt::format("{}: mesh is not closed{}: {} boundary edges, 0 non-manifold edges",
                                       mesh->source_name, repaired, r.boundary_edges);
  if (r.boundary_edges > defaults.max_open_boundary_edges)
    return Error{fmt::format("{} (a closed mesh is required; --allow-open caps at most {} boundary edges)",
                             what, defaults.max_open_boundary_edges)};
  if (!args.allow_open)
    return Error{fmt::format(
        "{} (a closed mesh is required; --allow-open accepts it with its holes capped by flat fans)", what)};
  return mesh;
}

int run_build(const IstBuildArgs& args) {
  if (std::filesystem::path(args.out).extension() != ".ist")
    return fail(fmt::format("{}: the output file must end in .ist", args.out));
  const auto start = std::chrono::steady_clock::now();
  auto mesh = load_build_mesh(args);
  if (!mesh) return fail(mesh.error().message);
  auto hash = collette::hash_file(args.mesh);
  if (!hash) return fail(hash.error().message);
  const double load_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ProgressBar bar("packing");
  collette::IstBuildOptions options{.sphere_count = args.spheres,
                                    .voxel_size = args.voxel,
                                    .max_radius = args.max_radius,
                                    .meters_per_unit = args.meters_per_unit,
                                    .progress = [&bar](double f) { bar.update(f); }};
  auto built = collette::build_ist_asset(*mesh, *hash, options);
  bar.finish();
  if (!built) return fail(built.error().message);
  built->asset.meta.build_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (auto saved = collette::save_ist(args.out, built->asset); !saved) return fail(saved.error().message);
  if (!args.preview.empty()) {
    std::vector<Sphere> leaves(built->asset.tree.leaves().begin(), built->asset.tree.leaves().end());
    if (auto png = collette::write_packing_preview(leaves, args.preview, {}); !png)
      return fail(png.error().message);
  }
  const auto& p = built->packing;
  const auto& tree = built->asset.tree;
  const auto& m = built->mesh;
  const std::string assumed = mesh_assumptions(m);
  const std::string repaired = mesh_repairs(m);
  if (args.json) {
    nlohmann::json j = {{"mesh", args.mesh},
                        {"output", args.out},
                        {"triangles", m.triangle_count},
                        {"spheres", p.sphere_count},
                        {"mesh_volume", p.mesh_volume},
                        {"sphere_volume", p.sphere_volume},
                        {"coverage", p.coverage},
                        {"max_gap", p.max_gap},
                        {"build_seconds", built->asset.meta.build_seconds},
                        {"load_seconds", load_seconds},
                        {"packing_seconds", p.build_seconds},
                        {"tree_seconds", built->tree_seconds},
                        {"voxel_size", p.voxel_size},
                        {"min_radius", p.min_radius},
                        {"max_radius", p.max_radius},
                        {"nodes", tree.node_count()},
                        {"depth", tree.depth()},
                        {"arity", tree.arity()},
                        {"repaired",
                         {{"degenerate_faces", m.degenerate_faces},
                          {"duplicate_faces", m.duplicate_faces},
                          {"winding_flipped", m.winding_flipped}}},
                        {"welded_vertices", m.welded_vertices},
                        {"open_boundary_edges", m.assumed_open ? m.boundary_edges : 0},
                        {"assumed", assumed}};
    if (!args.preview.empty()) j["preview"] = args.preview;
    std::printf("%s\n", j.dump(2).c_str());
  } else {
    std::printf("%s: %lld triangles -> %s\n", args.mesh.c_str(), static_cast<long long>(m.triangle_count),
                args.out.c_str());
    if (!repaired.empty()) std::printf("  repaired: %s\n", repaired.c_str());
    if (!assumed.empty()) std::printf("  assumed: %s\n", assumed.c_str());
    std::printf("  spheres %lld, coverage %.1f%% (sphere volume %.6g of %.6g), max gap %.4g\n",
                static_cast<long long>(p.sphere_count), 100.0 * p.coverage, p.sphere_volume, p.mesh_volume,
                p.max_gap);
    std::printf("  radii %.4g..%.4g, voxel %.4g; tree: %d nodes, depth %d\n", p.min_radius, p.max_radius,
                p.voxel_size, tree.node_count(), tree.depth());
    std::printf("  built in %.2f s (mesh %.2f s, packing %.2f s, tree %.2f s)\n",
                built->asset.meta.build_seconds, load_seconds, p.build_seconds, built->tree_seconds);
  }
  return 0;
}

int run_info(const IstInfoArgs& args) {
  auto asset = collette::load_ist(args.file);
  if (!asset) return fail(asset.error().message);
  const auto& tree = asset->tree;
  const auto& m = asset->meta;
  const auto& root = tree.root();
  // format 2 is format 1 and the surface section
  const unsigned format = asset->surface ? 2u : 1u;
  const std::size_t surface_triangles = asset->surface ? asset->surface->triangles.size() : 0;
  double min_r = 1e300, max_r = 0.0;
  for (const Sphere& s : tree.leaves()) {
    min_r = std::min(min_r, static_cast<double>(s.radius));
    max_r = std::max(max_r, static_cast<double>(s.radius));
  }
  if (args.json) {
    nlohmann::json j = {{"file", args.file},
                        {"format_version", format},
                        {"surface_triangles", surface_triangles},
                        {"spheres", tree.leaf_count()},
                        {"nodes", tree.node_count()},
                        {"depth", tree.depth()},
                        {"arity", tree.arity()},
                        {"sphere_volume", tree.total_volume()},
                        {"mesh_volume", m.mesh_volume},
                        {"coverage", m.coverage},
                        {"max_gap", m.max_gap},
                        {"build_seconds", m.build_seconds},
                        {"meters_per_unit", m.meters_per_unit},
                        {"source_mesh_hash", fmt::format("{:016x}", m.source_mesh_hash)},
                        {"min_radius", min_r},
                        {"max_radius", max_r},
                        {"bounding_sphere", {root.x, root.y, root.z, root.radius}}};
    std::printf("%s\n", j.dump(2).c_str());
  } else {
    std::printf("%s: Inner Sphere Tree, format %u\n", args.file.c_str(), format);
    std::printf("  spheres %d (radii %.4g..%.4g), nodes %d, depth %d, arity %d\n", tree.leaf_count(), min_r,
                max_r, tree.node_count(), tree.depth(), tree.arity());
    std::printf("  coverage %.1f%% (sphere volume %.6g of mesh volume %.6g), max gap %.4g\n",
                100.0 * m.coverage, tree.total_volume(), m.mesh_volume, m.max_gap);
    std::printf("  units: %g m per unit; source mesh hash %016llx; built in %.2f s\n", m.meters_per_unit,
                static_cast<unsigned long long>(m.source_mesh_hash), m.build_seconds);
    if (asset->surface)
      std::printf("  surface: %zu vertices, %zu triangles (the proxy rests on it)\n", asset->surface->vertices.size(),
                  surface_triangles);
    else
      std::printf("  surface: none (the proxy rests on the spheres, smoothed)\n");
  }
  return 0;
}

int run_preview(const IstPreviewArgs& args) {
  auto asset = collette::load_ist(args.file);
  if (!asset) return fail(asset.error().message);
  std::vector<Sphere> leaves(asset->tree.leaves().begin(), asset->tree.leaves().end());
  collette::PreviewOptions options;
  options.width = args.width;
  options.height = args.height;
  options.section = args.section;
  if (auto png = collette::write_packing_preview(leaves, args.out, options); !png)
    return fail(png.error().message);
  std::printf("%s: %zu spheres%s -> %s\n", args.file.c_str(), leaves.size(),
              args.section ? " (half section)" : "", args.out.c_str());
  return 0;
}

}  // namespace

void add_ist_commands(CLI::App& app, CommandRunner& runner) {
  auto* ist = app.add_subcommand("ist", "build, inspect and picture Inner Sphere Tree (.ist) files");
  ist->require_subcommand(1);

  static IstBuildArgs build;
  auto* b = ist->add_subcommand("build", "fill a closed mesh with spheres and write the tree to a .ist file");
  b->add_option("mesh", build.mesh, "mesh file (OBJ, STL, PLY, OFF, ... anything assimp reads)")
      ->required()
      ->check(CLI::ExistingFile);
  b->add_option("-o,--output", build.out, "output .ist file (written atomically)")->required();
  b->add_option("--spheres", build.spheres, "target number of spheres")
      ->default_val(10000)
      ->check(CLI::Range(1, 10000000));
  b->add_option("--voxel", build.voxel, "distance-field voxel size in mesh units (0 = automatic)")
      ->default_val(0.0)
      ->check(CLI::NonNegativeNumber);
  b->add_option(
       "--max-radius", build.max_radius,
       "largest sphere radius in mesh units (0 = unbounded; bounded, a thick object is as full under "
       "its faces as on average)")
      ->default_val(0.0)
      ->check(CLI::NonNegativeNumber);
  b->add_option("--meters-per-unit", build.meters_per_unit, "length of one mesh unit in metres")
      ->default_val(1.0)
      ->check(CLI::PositiveNumber);
  b->add_option("--preview", build.preview, "also write a PNG picture of the packing");
  b->add_flag(
      "--allow-open", build.allow_open,
      fmt::format(
          "accept a mesh that stays open after repair (at most {} boundary edges; holes capped by flat fans)",
          collette::MeshLoadOptions{}.max_open_boundary_edges));
  b->add_flag("--json", build.json, "print one JSON object");
  b->callback([&runner] { runner = [] { return run_build(build); }; });

  static IstInfoArgs info;
  auto* i = ist->add_subcommand("info", "print what a .ist file holds");
  i->add_option("file", info.file, ".ist file")->required()->check(CLI::ExistingFile);
  i->add_flag("--json", info.json, "print one JSON object");
  i->callback([&runner] { runner = [] { return run_info(info); }; });

  static IstPreviewArgs preview;
  auto* p = ist->add_subcommand("preview", "draw the packing of a .ist file to a PNG");
  p->add_option("file", preview.file, ".ist file")->required()->check(CLI::ExistingFile);
  p->add_option("-o,--output", preview.out, "output PNG")->required();
  p->add_flag("--section", preview.section, "cut the packing in half to show the inside");
  p->add_option("--width", preview.width, "pixels")->default_val(800)->check(CLI::Range(16, 8192));
  p->add_option("--height", preview.height, "pixels")->default_val(800)->check(CLI::Range(16, 8192));
  p->callback([&runner] { runner = [] { return run_preview(preview); }; });
}

}  // namespace uh::cli
