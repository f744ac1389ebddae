#include "scene_document.hpp"

#include <algorithm>
#include <span>

#include <fmt/format.h>

#include "uh/collette/ist_file.hpp"
#include "uh/collette/mesh_import.hpp"
#include "uh/core/atomic_file_writer.hpp"
#include "uh/core/json_nesting.hpp"

namespace uh::service {
namespace {

using nlohmann::json;

json vec3_json(const Vec3& v) { return json::array({v.x, v.y, v.z}); }
json pose_json(const Pose& p) {
  return {{"position", vec3_json(p.position)},
          {"rotation", json::array({p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z})}};
}

// A relative path given by a client is relative to the service's folder: made absolute here,
// before the scene parser would resolve it against the scene file's folder.
void absolutise(json& holder, const char* key, const std::filesystem::path& dir) {
  const auto it = holder.find(key);
  if (it == holder.end() || !it->is_string()) return;
  const std::filesystem::path p(it->get<std::string>());
  if (!p.empty() && p.is_relative()) *it = (dir / p).lexically_normal().string();
}

// Every file a scene document names (a `mesh`, `ist` or device `file` anywhere in it; a relative
// one is relative to `base_dir`) is one the service may read: checked before the scene parser
// opens any of them, so that nothing outside the folders is touched, nor its existence told.
Status check_named_files(const json& node, const std::string& field, const std::filesystem::path& base_dir,
                         const ReadableFolders& folders) {
  if (node.is_object()) {
    for (const auto& [key, value] : node.items()) {
      const std::string inner = field.empty() ? key : field + "." + key;
      if ((key == "mesh" || key == "ist" || key == "file") && value.is_string()) {
        const std::filesystem::path named(value.get<std::string>());
        if (named.empty()) continue;
        if (Status s =
                folders.check(named.is_absolute() ? named : base_dir / named, "field '" + inner + "':");
            !s)
          return s;
      } else if (Status s = check_named_files(value, inner, base_dir, folders); !s) {
        return s;
      }
    }
  } else if (node.is_array()) {
    for (std::size_t i = 0; i < node.size(); ++i)
      if (Status s = check_named_files(node[i], fmt::format("{}[{}]", field, i), base_dir, folders); !s)
        return s;
  }
  return Ok{};
}

}  // namespace

Result<SceneDocument> SceneDocument::open_file(const std::filesystem::path& path,
                                               const ReadableFolders& folders) {
  if (Status inside = folders.check(path, "scene"); !inside) return inside.error();
  auto text = controllers::read_scene_file(path);
  if (!text) return text.error();
  // the files it names, before the parser opens them (a text too deep or not JSON is the parser's
  // to refuse, with its message)
  if (!folders.any_path() && json_nesting_depth(*text) <= kMaxJsonNesting) {
    const json named = json::parse(*text, nullptr, false);
    if (!named.is_discarded())
      if (Status inside = check_named_files(named, "", path.parent_path(), folders); !inside)
        return inside.error();
  }
  // the scene parser names what is wrong; the document is read only once it accepted the text
  auto scene = controllers::parse_scene(*text, path.string(), path.parent_path());
  if (!scene) return scene.error();
  SceneDocument d;
  d.folders_ = folders;
  d.doc_ = json::parse(*text);
  d.source_ = path.string();
  d.base_dir_ = path.parent_path();
  d.scene_ = std::move(scene).value();
  return d;
}

Result<SceneDocument> SceneDocument::open_default(const std::filesystem::path& cache_dir,
                                                  const ReadableFolders& folders) {
  auto file = controllers::write_default_scene(cache_dir);
  if (!file) return file.error();
  return open_file(*file, folders);
}

Status SceneDocument::apply(json candidate) {
  if (!folders_.any_path())
    if (Status inside = check_named_files(candidate, "", base_dir_, folders_); !inside) return inside;
  auto scene = controllers::parse_scene(candidate.dump(), source_, base_dir_);
  if (!scene) return scene.error();
  doc_ = std::move(candidate);
  scene_ = std::move(scene).value();
  return Ok{};
}

json* SceneDocument::find_object(json& doc, const std::string& name) {
  for (json& o : doc["objects"])
    if (o.value("name", "") == name) return &o;
  return nullptr;
}

Status SceneDocument::add_object(json object, const std::filesystem::path& dir) {
  absolutise(object, "mesh", dir);
  absolutise(object, "ist", dir);
  json candidate = doc_;
  candidate["objects"].push_back(std::move(object));
  // an explicit watch list is kept as it is (set_watch changes it); without one, all are watched
  return apply(std::move(candidate));
}

Status SceneDocument::add_inline_object(json object, const std::filesystem::path& mesh_file) {
  object["mesh"] = mesh_file.string();
  return add_object(std::move(object), mesh_file.parent_path());
}

Result<InlineMesh> write_inline_mesh(collette::TriangleMesh mesh, const std::filesystem::path& mesh_dir) {
  auto valid = collette::validate_mesh(std::move(mesh));
  if (!valid) return valid.error();
  const std::string obj = collette::obj_text(
      *valid, "an inline mesh sent to uh serve (add_object with mesh_binary), welded and checked");
  const std::uint64_t hash = collette::ist_hash_bytes(std::as_bytes(std::span<const char>(obj)));
  const auto path = mesh_dir / fmt::format("{:016x}.obj", hash);
  std::error_code ec;
  std::filesystem::create_directories(mesh_dir, ec);
  // the service's folders are its own business: the message names only the file kind
  if (ec) return Error{fmt::format("cannot create the folder for inline meshes: {}", ec.message())};
  // named by its content: a file already there holds this very mesh
  if (!std::filesystem::exists(path, ec))
    if (auto written = write_file_atomically(path, obj); !written)
      return Error{"the inline mesh could not be written to the service's cache"};
  return InlineMesh{path, valid->report};
}

void remove_inline_mesh(const std::filesystem::path& mesh_file, const std::filesystem::path& cache_dir) {
  std::error_code ec;
  std::filesystem::remove(mesh_file, ec);
  // the packing cache names its files "<mesh stem>-<hash>-...ist" (controllers::load_shape_tree)
  const std::string prefix = mesh_file.stem().string() + "-";
  std::vector<std::filesystem::path> made;
  for (std::filesystem::directory_iterator it(cache_dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::filesystem::path& p = it->path();
    if (p.filename().string().rfind(prefix, 0) == 0 && p.extension() == ".ist") made.push_back(p);
  }
  for (const auto& p : made) std::filesystem::remove(p, ec);
}

Status SceneDocument::remove_object(const std::string& name) {
  json candidate = doc_;
  json& objects = candidate["objects"];
  const auto before = objects.size();
  for (auto it = objects.begin(); it != objects.end(); ++it)
    if (it->value("name", "") == name) {
      objects.erase(it);
      break;
    }
  if (objects.size() == before) return Error{fmt::format("no object is named '{}'", name)};
  if (candidate.contains("watch") && candidate["watch"].is_array()) {
    json kept = json::array();
    for (const json& w : candidate["watch"])
      if (!(w.is_string() && w.get<std::string>() == name)) kept.push_back(w);
    candidate["watch"] = std::move(kept);
  }
  if (objects.empty()) return Error{fmt::format("'{}' is the last object; a scene needs at least one", name)};
  return apply(std::move(candidate));
}

Status SceneDocument::set_pose(const std::string& name, const json& pose) {
  json candidate = doc_;
  json* object = find_object(candidate, name);
  if (object == nullptr) return Error{fmt::format("no object is named '{}'", name)};
  (*object)["pose"] = pose;
  return apply(std::move(candidate));
}

Status SceneDocument::set_watch(const std::vector<std::string>& names) {
  json candidate = doc_;
  candidate["watch"] = names;
  return apply(std::move(candidate));
}

Status SceneDocument::set_device(json device, const std::filesystem::path& dir) {
  if (const auto config = device.find("config"); config != device.end() && config->is_object())
    absolutise(*config, "file", dir);
  json candidate = doc_;
  candidate["tool"]["device"] = std::move(device);
  return apply(std::move(candidate));
}

Status SceneDocument::set_tool(json patch, const std::filesystem::path& dir) {
  absolutise(patch, "mesh", dir);
  absolutise(patch, "ist", dir);
  if (const auto device = patch.find("device"); device != patch.end() && device->is_object())
    if (const auto config = device->find("config"); config != device->end() && config->is_object())
      absolutise(*config, "file", dir);
  json candidate = doc_;
  candidate["tool"].merge_patch(patch);
  return apply(std::move(candidate));
}

Status SceneDocument::set_rates(std::optional<double> haptic_hz, std::optional<double> collision_hz) {
  json candidate = doc_;
  if (haptic_hz) candidate["rates"]["haptic_hz"] = *haptic_hz;
  if (collision_hz) candidate["rates"]["collision_hz"] = *collision_hz;
  return apply(std::move(candidate));
}

json describe_scene(const controllers::Scene& scene) {
  json objects = json::array();
  for (const auto& o : scene.objects) {
    const bool watched = std::find(scene.watch.begin(), scene.watch.end(), o.name) != scene.watch.end();
    objects.push_back({{"name", o.name},
                       {"pose", pose_json(o.pose)},
                       {"watched", watched},
                       {"has_mesh", !o.shape.mesh.empty()}});
  }
  return {{"name", scene.name},
          {"objects", std::move(objects)},
          {"tool",
           {{"name", scene.tool().name},
            {"has_mesh", !scene.tool().shape.mesh.empty()},
            {"device", scene.tool().device.driver}}},
          {"haptic_hz", scene.haptic_hz},
          {"collision_hz", scene.collision_hz}};
}

namespace {

// a soft object's drawn surface (its mesh refined), in the order of its deformed vertices
Result<json> soft_mesh(const controllers::SceneShape& shape, const std::string& name) {
  auto surface = controllers::load_soft_surface(shape);
  if (!surface) return surface.error();
  collette::TriangleMesh mesh;
  for (const auto& v : surface->vertices) mesh.vertices.push_back({v.x(), v.y(), v.z()});
  mesh.triangles = surface->triangles;
  json out = collette::mesh_json(mesh, 1.0);
  out["object"] = name;
  out["soft"] = true;
  return out;
}

}  // namespace

Result<json> scene_mesh(const controllers::Scene& scene, const std::string& name) {
  const controllers::SceneShape* shape = nullptr;
  bool soft = false;
  for (const auto& o : scene.objects)
    if (o.name == name) {
      shape = &o.shape;
      soft = o.deformable.has_value();
    }
  for (const auto& tool : scene.tools)
    if (tool.name == name) shape = &tool.shape;
  if (shape == nullptr) return Error{fmt::format("no object or tool is named '{}'", name)};
  if (shape->mesh.empty())
    return Error{fmt::format("'{}' was given as a .ist file, which holds no mesh", name)};
  if (soft) return soft_mesh(*shape, name);
  auto mesh = collette::load_mesh(shape->mesh);
  if (!mesh) return mesh.error();
  json out = collette::mesh_json(*mesh, shape->meters_per_unit);
  out["object"] = name;
  return out;
}

}  // namespace uh::service
