// uh mesh convert
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "uh/collette/mesh_import.hpp"
#include "uh/core/atomic_file_writer.hpp"
#include "uh/core/regular_file.hpp"

namespace uh::cli {
namespace {

struct MeshConvertArgs {
  std::string input;
  std::string out;
  std::string comment;
  bool allow_open = false;
};

// The largest mesh JSON read (a mesh file's limit is load_mesh's own).
constexpr std::uint64_t kMaxMeshJsonBytes = 512ull << 20;

bool is_json(const std::string& path) { return std::filesystem::path(path).extension() == ".json"; }

// Any mesh load_mesh() reads, or the mesh JSON; either way welded, repaired, validated, oriented.
Result<collette::TriangleMesh> read_mesh(const std::string& path, const collette::MeshLoadOptions& options) {
  if (!is_json(path)) return collette::load_mesh(path, options);
  const std::string name = std::filesystem::path(path).filename().string();
  auto bytes = read_regular_file(path, kMaxMeshJsonBytes);
  if (!bytes) return bytes.error();
  auto mesh = collette::parse_mesh_json(*bytes, name);
  if (!mesh) return mesh.error();
  return collette::validate_mesh(std::move(*mesh), options);
}

int run_mesh_convert(const MeshConvertArgs& args) {
  const std::string ext = std::filesystem::path(args.out).extension().string();
  if (ext != ".obj" && ext != ".json")
    return fail(fmt::format("--output '{}': the mesh is written as .obj or .json", args.out));
  auto mesh = read_mesh(args.input, {.allow_open = args.allow_open});
  if (!mesh) return fail(mesh.error().message);
  const std::string text =
      ext == ".obj" ? collette::obj_text(*mesh, args.comment) : collette::mesh_json(*mesh).dump() + "\n";
  if (auto written = write_file_atomically(args.out, text); !written) return fail(written.error().message);
  std::printf("wrote %s: %zu vertices, %zu triangles%s\n", args.out.c_str(), mesh->vertices.size(),
              mesh->triangles.size(), mesh->report.winding_flipped ? " (its winding was inverted: flipped)" : "");
  return 0;
}

}  // namespace

void add_mesh_command(CLI::App& app, CommandRunner& runner) {
  auto* mesh = app.add_subcommand("mesh", "check and convert triangle meshes");
  mesh->require_subcommand(1);
  static MeshConvertArgs convert;
  auto* c = mesh->add_subcommand(
      "convert",
      "check a mesh (closed, 2-manifold, outward) and write it as OBJ or as the mesh JSON "
      "{\"vertices\": [x, y, z, ...], \"triangles\": [i, j, k, ...]}, welded, repaired and oriented as every "
      "reader of meshes here sees it; scripts that make meshes write that JSON and convert it");
  c->add_option("input", convert.input, "mesh file (anything `uh ist build` reads) or mesh JSON (.json)")
      ->required()
      ->check(CLI::ExistingFile);
  c->add_option("-o,--output", convert.out, "output .obj or .json (written atomically)")->required();
  c->add_option("--comment", convert.comment, "an OBJ comment line (what the mesh is, what made it)");
  c->add_flag("--allow-open", convert.allow_open,
              fmt::format("accept a mesh that stays open after repair (at most {} boundary edges)",
                          collette::MeshLoadOptions{}.max_open_boundary_edges));
  c->callback([&runner] { runner = [] { return run_mesh_convert(convert); }; });
}

}  // namespace uh::cli
