// The Python module `unrealhaptics`: the C API (uh.h) for Python, with numpy arrays in and out.
// Every call goes through libuh, so Python sees exactly what C, C# and the engines see.
//
// Threads: Python code only ever runs on the threads that call into the module; the haptic and
// collision threads never call Python (no tick callback is offered; contact events are queued
// and taken with Session.events()). Calls that may take long (opening, packing meshes, stopping,
// stepped runs, queries) release the GIL.

#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "uh/uh.h"

namespace py = pybind11;

namespace {

// Raised for every failed call; .status holds the uh_status name.
struct UhError {
  static PyObject* type;
};
PyObject* UhError::type = nullptr;

void check(uh_status status) {
  if (status == UH_OK) return;
  const std::string message = uh_last_error();
  py::object error = py::reinterpret_borrow<py::object>(UhError::type)(message);
  error.attr("status") = uh_status_name(status);
  PyErr_SetObject(UhError::type, error.ptr());
  throw py::error_already_set();
}

// Runs a C call without the GIL (the call does not touch Python objects), then checks it.
template <typename Call>
void call_released(Call&& call) {
  uh_status status = UH_OK;
  {
    py::gil_scoped_release release;
    status = call();
  }
  check(status);
}

py::array_t<double> vector_array(const double* values, py::ssize_t n) {
  py::array_t<double> a(n);
  std::copy(values, values + n, a.mutable_data());
  return a;
}

std::array<double, 3> vec3_of(const py::object& value, const char* name) {
  const auto a = py::cast<std::vector<double>>(value);
  if (a.size() != 3) throw py::value_error(std::string(name) + " must have 3 numbers (x, y, z)");
  return {a[0], a[1], a[2]};
}

std::array<double, 4> quat_of(const py::object& value, const char* name) {
  const auto a = py::cast<std::vector<double>>(value);
  if (a.size() != 4) throw py::value_error(std::string(name) + " must have 4 numbers (w, x, y, z)");
  return {a[0], a[1], a[2], a[3]};
}

py::object json_loads(const char* text) { return py::module_::import("json").attr("loads")(text); }

// ----- trees -----

struct QueryResult {
  double volume = 0.0;
  double volume_estimate = 0.0;
  py::array_t<double> direction;
  int pair_count = 0;
  double distance = 0.0;
};

class Ist {
 public:
  explicit Ist(uh_tree_id tree) : tree_(tree) {}
  ~Ist() { uh_tree_destroy(tree_); }
  Ist(const Ist&) = delete;
  Ist& operator=(const Ist&) = delete;

  static std::unique_ptr<Ist> load(const std::string& path) {
    uh_tree_id tree{0};
    call_released([&] { return uh_tree_load(path.c_str(), &tree); });
    return std::make_unique<Ist>(tree);
  }

  static std::unique_ptr<Ist> build(const std::string& mesh_path, std::int64_t spheres,
                                    double meters_per_unit) {
    uh_tree_build_def def = uh_default_tree_build_def();
    def.spheres = spheres;
    def.meters_per_unit = meters_per_unit;
    uh_tree_id tree{0};
    call_released([&] { return uh_tree_build(mesh_path.c_str(), &def, &tree); });
    return std::make_unique<Ist>(tree);
  }

  static std::unique_ptr<Ist> from_arrays(
      py::array_t<double, py::array::c_style | py::array::forcecast> vertices,
      py::array_t<std::int32_t, py::array::c_style | py::array::forcecast> triangles, std::int64_t spheres,
      double meters_per_unit) {
    if (vertices.ndim() != 2 || vertices.shape(1) != 3)
      throw py::value_error("vertices must have shape (n, 3)");
    if (triangles.ndim() != 2 || triangles.shape(1) != 3)
      throw py::value_error("triangles must have shape (m, 3)");
    uh_tree_build_def def = uh_default_tree_build_def();
    def.spheres = spheres;
    def.meters_per_unit = meters_per_unit;
    uh_tree_id tree{0};
    const double* v = vertices.data();
    const std::int32_t* t = triangles.data();
    const auto nv = static_cast<int32_t>(vertices.shape(0));
    const auto nt = static_cast<int32_t>(triangles.shape(0));
    call_released([&] { return uh_tree_build_from_arrays(v, nv, t, nt, &def, &tree); });
    return std::make_unique<Ist>(tree);
  }

  void save(const std::string& path) const {
    call_released([&] { return uh_tree_save(tree_, path.c_str()); });
  }

  uh_tree_info info() const {
    uh_tree_info info{};
    info.struct_size = sizeof info;
    check(uh_tree_get_info(tree_, &info));
    return info;
  }

  QueryResult query(const Ist& other, const py::object& position, const py::object& orientation) const {
    const auto p = vec3_of(position, "position");
    const auto q = quat_of(orientation, "orientation");
    uh_query_result r{};
    r.struct_size = sizeof r;
    call_released([&] { return uh_tree_query(tree_, other.tree_, p.data(), q.data(), &r); });
    return QueryResult{r.volume, r.volume_estimate, vector_array(r.direction, 3), r.pair_count, r.distance};
  }

  uh_tree_id handle() const { return tree_; }

 private:
  uh_tree_id tree_;
};

// ----- scenes -----

// A shape def from keyword arguments (exactly one source); `keep` holds strings and arrays alive.
struct ShapeArgs {
  std::optional<std::string> mesh, ist;
  const Ist* tree = nullptr;
  py::array_t<double, py::array::c_style | py::array::forcecast> vertices;
  py::array_t<std::int32_t, py::array::c_style | py::array::forcecast> triangles;
  bool has_arrays = false;

  uh_shape_def def(std::int64_t spheres, double meters_per_unit) const {
    uh_shape_def d = uh_default_shape_def();
    d.spheres = spheres;
    d.meters_per_unit = meters_per_unit;
    if (mesh) d.mesh_path = mesh->c_str();
    if (ist) d.ist_path = ist->c_str();
    if (tree != nullptr) d.tree = tree->handle();
    if (has_arrays) {
      if (vertices.ndim() != 2 || vertices.shape(1) != 3)
        throw py::value_error("vertices must have shape (n, 3)");
      if (triangles.ndim() != 2 || triangles.shape(1) != 3)
        throw py::value_error("triangles must have shape (m, 3)");
      d.vertices = vertices.data();
      d.vertex_count = static_cast<int32_t>(vertices.shape(0));
      d.indices = triangles.data();
      d.triangle_count = static_cast<int32_t>(triangles.shape(0));
    }
    return d;
  }
};

ShapeArgs shape_args(const py::object& mesh, const py::object& ist, const py::object& tree,
                     const py::object& vertices, const py::object& triangles) {
  ShapeArgs s;
  if (!mesh.is_none()) s.mesh = py::str(mesh).cast<std::string>();
  if (!ist.is_none()) s.ist = py::str(ist).cast<std::string>();
  if (!tree.is_none()) s.tree = &tree.cast<const Ist&>();
  if (!vertices.is_none() || !triangles.is_none()) {
    if (vertices.is_none() || triangles.is_none())
      throw py::value_error("give vertices and triangles together");
    s.vertices = vertices;
    s.triangles = triangles;
    s.has_arrays = true;
  }
  return s;
}

class Scene {
 public:
  explicit Scene(uh_scene_id scene) : scene_(scene) {}
  ~Scene() { uh_scene_destroy(scene_); }
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;

  static std::unique_ptr<Scene> create(const std::string& name) {
    uh_scene_id scene{0};
    check(uh_scene_create(name.c_str(), &scene));
    return std::make_unique<Scene>(scene);
  }
  static std::unique_ptr<Scene> load(const py::object& path) {
    const std::optional<std::string> p =
        path.is_none() ? std::nullopt : std::optional(py::str(path).cast<std::string>());
    uh_scene_id scene{0};
    call_released([&] { return uh_scene_load(p ? p->c_str() : nullptr, &scene); });
    return std::make_unique<Scene>(scene);
  }
  static std::unique_ptr<Scene> parse(const std::string& json_text, const py::object& base_dir) {
    const std::optional<std::string> b =
        base_dir.is_none() ? std::nullopt : std::optional(py::str(base_dir).cast<std::string>());
    uh_scene_id scene{0};
    check(uh_scene_parse(json_text.c_str(), b ? b->c_str() : nullptr, &scene));
    return std::make_unique<Scene>(scene);
  }

  int add_object(const std::string& name, const py::object& mesh, const py::object& ist,
                 const py::object& tree, const py::object& vertices, const py::object& triangles,
                 std::int64_t spheres, double meters_per_unit, const py::object& position,
                 const py::object& orientation, bool watch) {
    const ShapeArgs shape = shape_args(mesh, ist, tree, vertices, triangles);
    uh_object_def def = uh_default_object_def();
    def.name = name.c_str();
    def.shape = shape.def(spheres, meters_per_unit);
    const auto p = vec3_of(position, "position");
    const auto q = quat_of(orientation, "orientation");
    std::copy(p.begin(), p.end(), def.position);
    std::copy(q.begin(), q.end(), def.orientation);
    def.watch = watch ? 1 : 0;
    int32_t index = -1;
    call_released([&] { return uh_scene_add_object(scene_, &def, &index); });
    return index;
  }

  void remove_object(const std::string& name) { check(uh_scene_remove_object(scene_, name.c_str())); }

  void set_object_pose(const std::string& name, const py::object& position, const py::object& orientation) {
    const auto p = vec3_of(position, "position");
    const auto q = quat_of(orientation, "orientation");
    check(uh_scene_set_object_pose(scene_, name.c_str(), p.data(), q.data()));
  }

  void watch(const std::string& name, bool on) { check(uh_scene_watch(scene_, name.c_str(), on ? 1 : 0)); }

  void set_tool(const py::kwargs& kwargs) {
    with_tool_def(kwargs, [&](const uh_tool_def& def) {
      call_released([&] { return uh_scene_set_tool(scene_, &def); });
    });
  }

  int add_tool(const py::kwargs& kwargs) {
    int32_t index = -1;
    with_tool_def(kwargs, [&](const uh_tool_def& def) {
      call_released([&] { return uh_scene_add_tool(scene_, &def, &index); });
    });
    return index;
  }

  void remove_tool(const std::string& name) { check(uh_scene_remove_tool(scene_, name.c_str())); }

  int tool_count() const {
    int32_t n = 0;
    check(uh_scene_tool_count(scene_, &n));
    return n;
  }

  void set_rates(double haptic_hz, double collision_hz) {
    check(uh_scene_set_rates(scene_, haptic_hz, collision_hz));
  }

  int object_count() const {
    int32_t n = 0;
    check(uh_scene_object_count(scene_, &n));
    return n;
  }

  uh_scene_id handle() const { return scene_; }

 private:
  // the tool def of set_tool's / add_tool's keyword arguments, handed to `use` while the strings
  // and arrays it points into are alive
  template <typename Use>
  static void with_tool_def(const py::kwargs& kwargs, Use&& use);

  uh_scene_id scene_;
};

template <typename Use>
void Scene::with_tool_def(const py::kwargs& kwargs, Use&& use) {
  static const char* const known[] = {"name",
                                      "mesh",
                                      "ist",
                                      "tree",
                                      "vertices",
                                      "triangles",
                                      "spheres",
                                      "meters_per_unit",
                                      "mode",
                                      "law",
                                      "stiffness",
                                      "force_scale",
                                      "damping",
                                      "damping_full_volume",
                                      "mass_kg",
                                      "center_of_mass",
                                      "max_force_n",
                                      "max_torque_nm",
                                      "device",
                                      "config",
                                      "workspace_scale",
                                      "workspace_offset",
                                      "workspace_rotation",
                                      "tool_offset"};
  for (const auto& [key, value] : kwargs) {
    const std::string k = py::str(key);
    if (std::find_if(std::begin(known), std::end(known), [&](const char* n) { return k == n; }) ==
        std::end(known))
      throw py::type_error("got an unexpected keyword argument '" + k + "' for a tool");
  }
  const auto get = [&](const char* key) -> py::object {
    if (kwargs.contains(key)) return kwargs[key];
    return py::none();
  };
  uh_tool_def def = uh_default_tool_def();
  const ShapeArgs shape = shape_args(get("mesh"), get("ist"), get("tree"), get("vertices"), get("triangles"));
  def.shape =
      shape.def(kwargs.contains("spheres") ? kwargs["spheres"].cast<std::int64_t>() : def.shape.spheres,
                kwargs.contains("meters_per_unit") ? kwargs["meters_per_unit"].cast<double>() : 1.0);
  const std::string name = kwargs.contains("name") ? kwargs["name"].cast<std::string>() : "tool";
  def.name = name.c_str();
  if (kwargs.contains("mode")) {
    const std::string mode = kwargs["mode"].cast<std::string>();
    if (mode != "6dof" && mode != "3dof") throw py::value_error("mode must be '6dof' or '3dof'");
    def.mode = mode == "3dof" ? UH_FORCE_3DOF : UH_FORCE_6DOF;
  }
  if (kwargs.contains("law")) {
    const std::string law = kwargs["law"].cast<std::string>();
    if (law != "gradient" && law != "paper") throw py::value_error("law must be 'gradient' or 'paper'");
    def.law = law == "paper" ? UH_FORCE_LAW_PAPER : UH_FORCE_LAW_GRADIENT;
  }
  // each law has its own stiffness in its own unit: a value meant for the other would be wrong by
  // orders of magnitude, so it is refused rather than ignored
  if (def.law == UH_FORCE_LAW_GRADIENT && kwargs.contains("force_scale"))
    throw py::value_error(
        "force_scale is the paper law's stiffness [N/m^3]; the gradient law (the default) takes stiffness= "
        "[N/m^2] "
        "(or pass law='paper')");
  if (def.law == UH_FORCE_LAW_PAPER && kwargs.contains("stiffness"))
    throw py::value_error(
        "stiffness is the gradient law's [N/m^2]; the paper law takes force_scale= [N/m^3]");
  const auto number = [&](const char* key, double& out) {
    if (kwargs.contains(key)) out = kwargs[key].cast<double>();
  };
  number("stiffness", def.stiffness);
  number("force_scale", def.force_scale);
  number("damping", def.damping);
  number("damping_full_volume", def.damping_full_volume);
  number("mass_kg", def.mass_kg);
  number("max_force_n", def.max_force_n);
  number("max_torque_nm", def.max_torque_nm);
  number("workspace_scale", def.workspace_scale);
  if (kwargs.contains("center_of_mass")) {
    const auto c = vec3_of(kwargs["center_of_mass"], "center_of_mass");
    std::copy(c.begin(), c.end(), def.center_of_mass);
  }
  if (kwargs.contains("workspace_offset")) {
    const auto c = vec3_of(kwargs["workspace_offset"], "workspace_offset");
    std::copy(c.begin(), c.end(), def.workspace_offset);
  }
  if (kwargs.contains("workspace_rotation")) {
    const auto c = quat_of(kwargs["workspace_rotation"], "workspace_rotation");
    std::copy(c.begin(), c.end(), def.workspace_rotation);
  }
  if (kwargs.contains("tool_offset")) {
    const auto c = vec3_of(kwargs["tool_offset"], "tool_offset");
    std::copy(c.begin(), c.end(), def.tool_offset);
  }
  const std::string driver = kwargs.contains("device") ? kwargs["device"].cast<std::string>() : "sim-line";
  def.device_driver = driver.c_str();
  std::string config;
  if (kwargs.contains("config")) {
    const py::object c = kwargs["config"];
    config = py::isinstance<py::str>(c) ? c.cast<std::string>()
                                        : py::module_::import("json").attr("dumps")(c).cast<std::string>();
    def.device_config_json = config.c_str();
  }
  use(def);
}

// ----- sessions -----

struct State {
  double time_s = 0.0;
  py::array_t<double> tool_position, tool_orientation, force, torque;
  int contact_pairs = 0;
  std::uint64_t haptic_ticks = 0, missed_deadlines = 0;
  double haptic_rate_hz = 0.0, collision_rate_hz = 0.0;
  std::uint32_t buttons = 0;
  py::array_t<double> handle_position;
};

struct ContactEvent {
  std::string kind;  // "begin" or "end"
  int object = -1;
  int tool = -1;
  double time_s = 0.0, volume = 0.0;
  int pairs = 0;
};

class Session {
 public:
  explicit Session(uh_session_id s) : session_(s) {}
  ~Session() { close(); }
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  static uh_session_def session_def(const py::object& cache_dir, double haptic_hz, double collision_hz,
                                    bool raise_priority, const py::object& proxy, std::string& cache) {
    uh_session_def def = uh_default_session_def();
    if (!proxy.is_none() && !py::isinstance<py::bool_>(proxy))
      throw py::type_error("Session.open: proxy is None (the scene's), True or False, got " +
                           py::repr(proxy).cast<std::string>());
    def.proxy = proxy.is_none() ? -1 : (proxy.cast<bool>() ? 1 : 0);
    def.haptic_hz = haptic_hz;
    def.collision_hz = collision_hz;
    def.raise_priority = raise_priority ? 1 : 0;
    if (!cache_dir.is_none()) {
      cache = py::str(cache_dir).cast<std::string>();
      def.cache_dir = cache.c_str();
    }
    return def;
  }

  static std::unique_ptr<Session> open(const py::object& scene, const py::object& cache_dir, double haptic_hz,
                                       double collision_hz, bool raise_priority, const py::object& proxy) {
    std::string cache;
    const uh_session_def def = session_def(cache_dir, haptic_hz, collision_hz, raise_priority, proxy, cache);
    uh_session_id s{0};
    if (py::isinstance<Scene>(scene)) {
      const uh_scene_id sc = scene.cast<const Scene&>().handle();
      call_released([&] { return uh_session_create(sc, &def, &s); });
    } else {
      // a file (or the default scene), opened with the session's settings
      uh_scene_id sc{0};
      const std::optional<std::string> path =
          scene.is_none() ? std::nullopt : std::optional(py::str(scene).cast<std::string>());
      call_released([&] { return uh_scene_load(path ? path->c_str() : nullptr, &sc); });
      const uh_status status = [&] {
        py::gil_scoped_release release;
        const uh_status created = uh_session_create(sc, &def, &s);
        uh_scene_destroy(sc);
        return created;
      }();
      check(status);
    }
    return std::make_unique<Session>(s);
  }

  void start() {
    call_released([&] { return uh_session_start(session_); });
  }

  State state(int tool) const {
    uh_state st{};
    st.struct_size = sizeof st;
    check(uh_session_tool_state(session_, tool, &st));
    return State{st.time_s,
                 vector_array(st.tool_position, 3),
                 vector_array(st.tool_orientation, 4),
                 vector_array(st.force, 3),
                 vector_array(st.torque, 3),
                 st.contact_pairs,
                 st.haptic_ticks,
                 st.missed_deadlines,
                 st.haptic_rate_hz,
                 st.collision_rate_hz,
                 st.buttons,
                 vector_array(st.handle_position, 3)};
  }

  std::vector<ContactEvent> events() {
    std::vector<ContactEvent> out;
    uh_contact_event e{};
    e.struct_size = sizeof e;
    for (int32_t has = 1;;) {
      check(uh_session_poll_event(session_, &e, &has));
      if (has == 0) break;
      out.push_back(
          {e.kind == UH_CONTACT_BEGIN ? "begin" : "end", e.object, e.tool, e.time_s, e.volume, e.pairs});
    }
    return out;
  }

  void set_object_pose(int object, const py::object& position, const py::object& orientation) {
    const auto p = vec3_of(position, "position");
    const auto q = quat_of(orientation, "orientation");
    check(uh_session_set_object_pose(session_, object, p.data(), q.data()));
  }

  py::object stop() {
    call_released([&] { return uh_session_stop(session_); });
    return report();
  }

  bool ended_by_itself() {
    std::int32_t ended = 0;
    check(uh_session_ended(session_, &ended));
    return ended != 0;
  }

  py::object run_stepped(double seconds, int ticks_per_collision_step) {
    call_released([&] { return uh_session_run_stepped(session_, seconds, ticks_per_collision_step); });
    return report();
  }

  py::object report() const {
    const char* json = nullptr;
    check(uh_session_report_json(session_, &json));
    return json_loads(json);
  }

  // a soft object's deformed surface: (N, 3) float32 vertices [m, object frame], newest step
  py::array_t<float> deformed_vertices(int object) const {
    int32_t n = 0;
    check(uh_session_soft_vertex_count(session_, object, &n));
    py::array_t<float> xyz({static_cast<py::ssize_t>(n), py::ssize_t{3}});
    float* data = xyz.mutable_data();
    call_released([&] { return uh_session_soft_vertices(session_, object, data, n, nullptr); });
    return xyz;
  }

  // its triangles: (M, 3) int32 indices into deformed_vertices' rows
  py::array_t<std::int32_t> soft_triangles(int object) const {
    int32_t n = 0;
    check(uh_session_soft_triangle_count(session_, object, &n));
    py::array_t<std::int32_t> indices({static_cast<py::ssize_t>(n), py::ssize_t{3}});
    check(uh_session_soft_triangles(session_, object, indices.mutable_data(), n));
    return indices;
  }

  std::vector<std::string> tool_names() const { return names(uh_session_tool_count, uh_session_tool_name); }
  std::vector<std::string> object_names() const {
    return names(uh_session_object_count, uh_session_object_name);
  }

  // the session's objects' or tools' names, by their count and name functions
  std::vector<std::string> names(uh_status (*count)(uh_session_id, int32_t*),
                                 uh_status (*name_of)(uh_session_id, int32_t, const char**)) const {
    int32_t n = 0;
    check(count(session_, &n));
    std::vector<std::string> out;
    for (int32_t i = 0; i < n; ++i) {
      const char* name = nullptr;
      check(name_of(session_, i, &name));
      out.emplace_back(name);
    }
    return out;
  }

  // stops (zero force, joins every thread) and frees; idempotent
  void close() {
    if (session_.bits == 0) return;
    const uh_session_id s = std::exchange(session_, uh_session_id{0});
    if (PyGILState_Check() != 0) {
      py::gil_scoped_release release;
      uh_session_destroy(s);
    } else {
      uh_session_destroy(s);
    }
  }

 private:
  uh_session_id session_;
};

}  // namespace

PYBIND11_MODULE(unrealhaptics, m) {
  m.doc() = "UnrealHaptics: haptic sessions and Inner Sphere Tree queries (through the C API, libuh)";
  m.attr("__version__") = uh_version_string();
  m.attr("api_version") = uh_api_version();
  if (uh_api_version() != UH_API_VERSION)
    throw std::runtime_error("unrealhaptics: libuh has another API version");
  UhError::type = PyErr_NewExceptionWithDoc("unrealhaptics.UhError",
                                            "A failed UnrealHaptics call; the message says what was wrong, "
                                            ".status names the uh_status.",
                                            PyExc_RuntimeError, nullptr);
  m.attr("UhError") = py::handle(UhError::type);

  py::class_<QueryResult>(m, "QueryResult", "The overlap of two trees at one pose (metres, A's frame).")
      .def_readonly("volume", &QueryResult::volume, "intersection volume of the packings [m^3]")
      .def_readonly("volume_estimate", &QueryResult::volume_estimate,
                    "volume / (coverage_a * coverage_b): estimate of the meshes' overlap [m^3]")
      .def_readonly(
          "direction", &QueryResult::direction,
          "(3,) unit direction of the force the gradient law puts on B (minus the gradient of the overlap "
          "volume); zero when apart")
      .def_readonly("pair_count", &QueryResult::pair_count, "overlapping leaf sphere pairs")
      .def_readonly("distance", &QueryResult::distance,
                    "separation when apart (upper bound) [m]; 0 when overlapping");

  py::class_<Ist>(m, "Ist", "An Inner Sphere Tree (immutable; lengths in metres).")
      .def_static("load", &Ist::load, py::arg("path"), "Loads a .ist file.")
      .def_static("build", &Ist::build, py::arg("mesh"), py::arg("spheres") = 10000,
                  py::arg("meters_per_unit") = 1.0,
                  "Packs a closed mesh file with about `spheres` spheres and builds the tree.")
      .def_static("from_arrays", &Ist::from_arrays, py::arg("vertices"), py::arg("triangles"),
                  py::arg("spheres") = 10000, py::arg("meters_per_unit") = 1.0,
                  "Same from a closed mesh as arrays: vertices (n, 3), triangles (m, 3) counter-clockwise "
                  "from outside.")
      .def("save", &Ist::save, py::arg("path"), "Writes the tree as a .ist file (metres).")
      .def_property_readonly("leaf_count", [](const Ist& t) { return t.info().leaf_count; })
      .def_property_readonly("coverage", [](const Ist& t) { return t.info().coverage; })
      .def_property_readonly("mesh_volume", [](const Ist& t) { return t.info().mesh_volume; })
      .def_property_readonly("radius", [](const Ist& t) { return t.info().radius; })
      .def("query", &Ist::query, py::arg("other"), py::kw_only(),
           py::arg("position") = py::make_tuple(0.0, 0.0, 0.0),
           py::arg("orientation") = py::make_tuple(1.0, 0.0, 0.0, 0.0),
           "Overlap of `other` placed at (position, orientation (w, x, y, z)) in this tree's frame.");

  py::class_<Scene>(m, "Scene", "A scene description (objects, tool and device, watched pairs, rates).")
      .def_static("create", &Scene::create, py::arg("name") = "scene", "An empty scene.")
      .def_static("load", &Scene::load, py::arg("path") = py::none(),
                  "A scene file; None: the default scene.")
      .def_static("parse", &Scene::parse, py::arg("json"), py::arg("base_dir") = py::none(),
                  "Scene JSON text.")
      .def("add_object", &Scene::add_object, py::arg("name"), py::kw_only(), py::arg("mesh") = py::none(),
           py::arg("ist") = py::none(), py::arg("tree") = py::none(), py::arg("vertices") = py::none(),
           py::arg("triangles") = py::none(), py::arg("spheres") = 10000, py::arg("meters_per_unit") = 1.0,
           py::arg("position") = py::make_tuple(0.0, 0.0, 0.0),
           py::arg("orientation") = py::make_tuple(1.0, 0.0, 0.0, 0.0), py::arg("watch") = true,
           "Adds an object from exactly one of mesh, ist, tree or vertices+triangles; returns its index.")
      .def("remove_object", &Scene::remove_object, py::arg("name"))
      .def("set_object_pose", &Scene::set_object_pose, py::arg("name"), py::arg("position"),
           py::arg("orientation"))
      .def("watch", &Scene::watch, py::arg("name"), py::arg("on") = true)
      .def("add_tool", &Scene::add_tool,
           "Adds a tool after the scene's tools, each on its own device (the keywords of set_tool); "
           "returns its index.")
      .def("remove_tool", &Scene::remove_tool, py::arg("name"))
      .def_property_readonly("tool_count", &Scene::tool_count)
      .def("set_tool", &Scene::set_tool,
           "Sets the first tool: shape (mesh=/ist=/tree=/vertices=+triangles=, spheres=, meters_per_unit=), "
           "force "
           "law "
           "(mode='6dof'|'3dof', law='gradient'|'paper', stiffness= [N/m^2, gradient], force_scale= [N/m^3, "
           "paper], damping=, damping_full_volume=, mass_kg=, center_of_mass=, "
           "max_force_n=, "
           "max_torque_nm=), device=driver name, config=dict or JSON text, workspace_scale=, "
           "workspace_offset=, "
           "workspace_rotation=, tool_offset= (the tool's origin in the handle frame [m]).")
      .def("set_rates", &Scene::set_rates, py::arg("haptic_hz"), py::arg("collision_hz"))
      .def_property_readonly("object_count", &Scene::object_count);

  py::class_<State>(m, "State", "The newest state of a session (world frame, SI units).")
      .def_readonly("time_s", &State::time_s)
      .def_readonly("tool_position", &State::tool_position, "(3,) [m]")
      .def_readonly("tool_orientation", &State::tool_orientation, "(4,) w, x, y, z")
      .def_readonly("force", &State::force, "(3,) force sent to the device [N]")
      .def_readonly("torque", &State::torque, "(3,) torque sent to the device [N m]")
      .def_readonly("contact_pairs", &State::contact_pairs)
      .def_readonly("haptic_ticks", &State::haptic_ticks)
      .def_readonly("missed_deadlines", &State::missed_deadlines)
      .def_readonly("haptic_rate_hz", &State::haptic_rate_hz)
      .def_readonly("collision_rate_hz", &State::collision_rate_hz)
      .def_readonly("buttons", &State::buttons, "the device's buttons (bit i: button i)")
      .def_readonly("handle_position", &State::handle_position,
                    "(3,) where the handle puts the tool [m]: tool_position without a proxy; with one, the tool "
                    "rests on the surface above it");

  py::class_<ContactEvent>(m, "ContactEvent", "A contact between a tool and a watched object began or ended.")
      .def_readonly("kind", &ContactEvent::kind, "'begin' or 'end'")
      .def_readonly("object", &ContactEvent::object, "index of the object in the scene")
      .def_readonly("tool", &ContactEvent::tool, "index of the tool in the scene")
      .def_readonly("time_s", &ContactEvent::time_s)
      .def_readonly("volume", &ContactEvent::volume, "[m^3] (0 at 'end')")
      .def_readonly("pairs", &ContactEvent::pairs)
      .def("__repr__", [](const ContactEvent& e) {
        return "ContactEvent(" + e.kind + ", object=" + std::to_string(e.object) +
               ", time_s=" + std::to_string(e.time_s) + ")";
      });

  py::class_<Session>(
      m, "Session",
      "A scene running. Use as a context manager: leaving the block always stops (zero force, "
      "threads joined) and closes.")
      .def_static("open", &Session::open, py::arg("scene") = py::none(), py::kw_only(),
                  py::arg("cache_dir") = py::none(), py::arg("haptic_hz") = 0.0,
                  py::arg("collision_hz") = -1.0, py::arg("raise_priority") = false, py::arg("proxy") = py::none(),
                  "Opens a session of a scene file path, a Scene, or None (the default scene). proxy: None (the "
                  "scene's force.proxy), True (the 6-DOF proxy: the tool never passes through a surface) or False "
                  "(the penalty path).")
      .def("start", &Session::start, "Starts the haptic, collision and monitor threads; returns at once.")
      .def("state", &Session::state, py::arg("tool") = 0,
           "The newest state of a tool (the first by default; never waits for its haptic thread).")
      .def("events", &Session::events, "Contact events queued since the last call, oldest first.")
      .def("set_object_pose", &Session::set_object_pose, py::arg("object"), py::arg("position"),
           py::arg("orientation"))
      .def_property_readonly("ended_by_itself", &Session::ended_by_itself,
                             "True when the running session ended by itself: a device faulted or a thread "
                             "ended (every device was sent zero at its next tick); stop() then raises the "
                             "cause. False while it runs as it should, before start() and after stop().")
      .def("stop", &Session::stop,
           "Zero force, joins every thread; returns the report (the `uh run --json` object). Idempotent.")
      .def("run_stepped", &Session::run_stepped, py::arg("seconds"), py::arg("ticks_per_collision_step") = 4,
           "Runs deterministically on this thread in simulated time; returns the report.")
      .def("report", &Session::report)
      .def_property_readonly("object_names", &Session::object_names)
      .def("deformed_vertices", &Session::deformed_vertices, py::arg("object"),
           "A soft object's deformed surface (its mesh, refined) as the newest simulation step left it: "
           "an (N, 3) float32 array [m, the object's frame]. UhError for a rigid object.")
      .def("soft_triangles", &Session::soft_triangles, py::arg("object"),
           "The triangles of a soft object's deformed surface: (M, 3) int32 rows of deformed_vertices.")
      .def_property_readonly("tool_names", &Session::tool_names, "The scene's tools, each on its own device.")
      .def("close", &Session::close, "Stops and frees the session. Idempotent.")
      .def(
          "__enter__", [](Session& s) -> Session& { return s; }, py::return_value_policy::reference)
      .def("__exit__", [](Session& s, const py::args&) { s.close(); });
}
