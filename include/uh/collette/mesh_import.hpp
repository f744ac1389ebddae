#pragma once
/// \file
/// Loading and validating triangle meshes (OBJ, STL, PLY, OFF and every other format assimp reads;
/// builds without assimp, such as the Windows build, read OBJ and STL with the in-tree reader).

#include <filesystem>
#include <string>
#include <string_view>

#include <nlohmann/json_fwd.hpp>

#include "uh/collette/triangle_mesh.hpp"
#include "uh/core/result.hpp"

namespace uh::collette {

/// How strictly load_mesh() / validate_mesh() treat a mesh (Box2D-style options aggregate).
struct MeshLoadOptions {
  /// Vertices closer than weld_tolerance * (bounding-box diagonal) are merged. 0 merges only
  /// bit-identical positions. STL files are unindexed, so welding is what makes them a mesh.
  double weld_tolerance = 1e-7;
  /// Accept meshes with at most max_open_boundary_edges boundary edges. The mesh is then kept as
  /// is, report.assumed_open is set and inside tests must use the generalised winding number
  /// (MeshInside does). Non-manifold edges and inconsistent orientation are still errors.
  bool allow_open = false;
  std::int64_t max_open_boundary_edges = 1000;
  /// Repair what can be repaired without guessing at the shape: drop degenerate triangles
  /// (repeated vertices after welding, or (near) zero area) and duplicate triangles (the same
  /// three vertices as an earlier one, in either winding: the first is kept), then number the
  /// remaining vertices and count the edges again. MeshReport says how many were dropped.
  /// false: such a mesh is refused.
  bool repair = true;
  /// A triangle is degenerate when twice its area is below this times the squared bbox diagonal.
  double degenerate_area_tolerance = 1e-14;
};

/// Reads a mesh file, welds vertices, repairs it (MeshLoadOptions::repair), validates it and fixes
/// an inverted winding.
///
/// Errors name the file and say what is wrong, e.g. "teapot.obj: mesh is not closed: 64 boundary
/// edges, 0 non-manifold edges (a closed 2-manifold mesh is required)"; they name no C++ option,
/// so that programs can show them as they are.
/// Missing, unreadable and empty files are errors too. All meshes in the file are merged. Setup
/// code only (allocates, reads files); any thread; not real-time safe.
Result<TriangleMesh> load_mesh(const std::filesystem::path& path, const MeshLoadOptions& options = {});

/// Reads the vertices and triangles of an OBJ or STL file with the in-tree reader, as they are:
/// no welding, no validation (load_mesh() does those). It is what load_mesh() reads with in builds
/// without assimp (the Windows build). OBJ: `v` and `f` lines (corners i, i/t, i//n or i/t/n; a
/// negative i counts back from the last vertex; faces with more than 3 corners are fanned from
/// their first corner, right for the convex faces exporters write), all else is ignored. STL:
/// binary when the file size is 84 + 50 n bytes for its n triangles, else ASCII. Coordinates are
/// rounded to float, as assimp keeps them, so both readers give the same mesh. Errors name the
/// file and line. Not real-time safe; any thread.
Result<TriangleMesh> read_obj_or_stl(const std::filesystem::path& path);

/// The same for a file's content already in memory; `name` names it in messages, and its
/// extension (.obj or .stl) chooses the format.
Result<TriangleMesh> parse_obj_or_stl(std::string_view bytes, const std::string& name);

/// The mesh as OBJ text (`v` and `f` lines, 1-based corners) after a `# comment` line when the
/// comment is not empty: the one OBJ writer, for meshes the project generates or receives and
/// hands on as files. Coordinates are written so they read back exactly.
std::string obj_text(const TriangleMesh& mesh, std::string_view comment);

/// The mesh as JSON, {"vertices": [x, y, z, ...], "triangles": [i, j, k, ...]} (flat arrays,
/// corners from 0): the one mesh-to-JSON writer (the museum page's pictures, the service's meshes).
/// Coordinates are multiplied by `scale`; with decimals >= 0 they are rounded to that many places
/// (a picture needs no more), else written so they read back exactly.
nlohmann::json mesh_json(const TriangleMesh& mesh, double scale = 1.0, int decimals = -1);

/// Reads that JSON (other fields are ignored): every coordinate a finite number, every corner an
/// index of a vertex. `name` names the mesh in messages. No welding, no validation (validate_mesh()).
Result<TriangleMesh> parse_mesh_json(std::string_view text, const std::string& name);

/// Welds, repairs, validates and orients an in-memory mesh the same way load_mesh() does (used by
/// load_mesh() and by code that builds meshes itself). `mesh.source_name` names it in messages.
/// On success mesh.report holds the counts. Not real-time safe.
Result<TriangleMesh> validate_mesh(TriangleMesh mesh, const MeshLoadOptions& options = {});

}  // namespace uh::collette
