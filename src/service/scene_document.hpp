#pragma once
// A scene as a client edits it: the scene file's JSON document plus the Scene the scene parser
// made of it. Every edit changes a copy of the document and goes through parse_scene() again, so
// the service accepts exactly what a scene file accepts, with the same messages; a refused edit
// leaves the document as it was.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "uh/collette/triangle_mesh.hpp"
#include "uh/controllers/scene.hpp"
#include "uh/core/regular_file.hpp"
#include "uh/core/result.hpp"

namespace uh::service {

class SceneDocument {
 public:
  /// A scene file; relative paths inside it are relative to its folder. The scene file and every
  /// file the scene names (meshes, .ist files, a device's `file`), now and after each edit, must be
  /// in `folders`: an edit naming another is refused.
  static Result<SceneDocument> open_file(const std::filesystem::path& path,
                                         const ReadableFolders& folders = {});
  /// The embedded default scene (written into `cache_dir`).
  static Result<SceneDocument> open_default(const std::filesystem::path& cache_dir,
                                            const ReadableFolders& folders = {});

  const controllers::Scene& scene() const { return scene_; }

  /// Paths given in edits (`mesh`, `ist`, a device's `file`) are relative to `dir` (the service's
  /// working directory), not to the scene file.
  Status add_object(nlohmann::json object, const std::filesystem::path& dir);
  /// An object whose mesh came inline, once write_inline_mesh() wrote it: added with that file
  /// as its `mesh`.
  Status add_inline_object(nlohmann::json object, const std::filesystem::path& mesh_file);
  Status remove_object(const std::string& name);
  Status set_pose(const std::string& name, const nlohmann::json& pose);
  Status set_watch(const std::vector<std::string>& names);
  Status set_device(nlohmann::json device, const std::filesystem::path& dir);
  /// Applies `patch` to the scene's `tool` as a JSON merge patch (RFC 7386: given fields replace,
  /// null removes, objects merge), e.g. {"force": {"damping": 3}} or {"mesh": "t.obj", "ist": null}.
  Status set_tool(nlohmann::json patch, const std::filesystem::path& dir);
  /// The scene's `rates`; a rate not given stays as it is.
  Status set_rates(std::optional<double> haptic_hz, std::optional<double> collision_hz);

 private:
  SceneDocument() = default;
  // parse_scene() on `candidate`; on success it becomes the document
  Status apply(nlohmann::json candidate);
  nlohmann::json* find_object(nlohmann::json& doc, const std::string& name);

  nlohmann::json doc_;
  ReadableFolders folders_;
  std::string source_;
  std::filesystem::path base_dir_;
  controllers::Scene scene_;
};

/// An inline mesh (a decoded `mesh_binary` frame, in mesh units) written for a scene: its file and
/// what validation found.
struct InlineMesh {
  std::filesystem::path file;
  collette::MeshReport report;
};

/// Welds, repairs and checks an inline mesh as a mesh file is (a mesh that is not closed is
/// refused with the counts) and writes it as OBJ into `mesh_dir` under a name made of its content
/// (so the packing cache finds the same mesh again). Any thread: the service runs it off its
/// network thread.
Result<InlineMesh> write_inline_mesh(collette::TriangleMesh mesh, const std::filesystem::path& mesh_dir);

/// Removes an inline mesh file and the packing cache's .ist files made of it (in `cache_dir`).
void remove_inline_mesh(const std::filesystem::path& mesh_file, const std::filesystem::path& cache_dir);

/// A scene for a `scene` reply: name, objects with poses, watched names, tool and device, rates.
nlohmann::json describe_scene(const controllers::Scene& scene);

/// The mesh of a scene's object or tool for a `mesh` reply: vertices in metres in the object's
/// frame and triangle indices, both flat. An error when there is no such object or it was given
/// as a .ist (which holds spheres, not a mesh).
Result<nlohmann::json> scene_mesh(const controllers::Scene& scene, const std::string& name);

}  // namespace uh::service
