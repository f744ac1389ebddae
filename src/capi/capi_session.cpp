// The C API's sessions: open, start or run stepped, poll state and events, stop, report, close.

#include <mutex>
#include <string>
#include <vector>

#include "capi_support.hpp"
#include "uh/controllers/haptic_session.hpp"

namespace uh::capi {

/// A session and what the C side hands out from it. `mutex` serialises the owner's calls
/// (everything but uh_session_poll and uh_session_tool_state, which HapticSession::state() makes
/// safe on its own).
struct SessionBox {
  std::mutex mutex;
  std::unique_ptr<controllers::HapticSession> session;
  std::vector<std::string> object_names;
  std::vector<std::string> tool_names;
  std::string report_json;
  bool stopped = false;
  uh_tick_fn tick_fn = nullptr;
  void* tick_user = nullptr;
  ScopedConnection tick_connection;
};

namespace {

HandleTable<SessionBox>& session_table() {
  static HandleTable<SessionBox> table(3);
  return table;
}

void fill_state(const controllers::SessionState& s, uh_state& out) {
  out.struct_size = sizeof(uh_state);
  out.time_s = s.time_s;
  out.tool_position[0] = s.tool_position_world.x;
  out.tool_position[1] = s.tool_position_world.y;
  out.tool_position[2] = s.tool_position_world.z;
  out.tool_orientation[0] = s.tool_orientation_world.w;
  out.tool_orientation[1] = s.tool_orientation_world.x;
  out.tool_orientation[2] = s.tool_orientation_world.y;
  out.tool_orientation[3] = s.tool_orientation_world.z;
  out.force[0] = s.force_world.x;
  out.force[1] = s.force_world.y;
  out.force[2] = s.force_world.z;
  out.torque[0] = s.torque_world.x;
  out.torque[1] = s.torque_world.y;
  out.torque[2] = s.torque_world.z;
  out.contact_pairs = s.contact_pairs;
  out.haptic_ticks = s.haptic_ticks;
  out.missed_deadlines = s.missed_deadlines;
  out.haptic_rate_hz = s.haptic_rate_hz;
  out.collision_rate_hz = s.collision_rate_hz;
  out.buttons = s.buttons;
  out.handle_position[0] = s.handle_position_world.x;
  out.handle_position[1] = s.handle_position_world.y;
  out.handle_position[2] = s.handle_position_world.z;
}

// haptic thread: hands each tick's state to the program's callback (real-time; no allocation)
void call_tick_callback(SessionBox& box, const controllers::SessionState& s) {
  uh_state state{};
  fill_state(s, state);
  box.tick_fn(box.tick_user, &state);
}

uh_status check_version(const char* function, int32_t api_version) {
  if (api_version != UH_API_VERSION)
    return fail(UH_ERROR_VERSION,
                fmt::format("{}: the program was compiled against UH_API_VERSION {}, this library "
                            "is version {} ({}); rebuild the program against this library's uh.h",
                            function, api_version, UH_API_VERSION, UH_VERSION_STRING));
  return UH_OK;
}

uh_session_def default_session_def() {
  uh_session_def def{};
  def.struct_size = sizeof def;
  def.collision_hz = -1.0;
  def.proxy = -1;
  return def;
}

uh_status open_session(const char* function, const controllers::Scene& scene, const uh_session_def& def,
                       uh_session_id* out) {
  if (scene.tools.empty())
    return fail(UH_ERROR_INVALID_ARGUMENT,
                fmt::format("{}: {} has no tool (uh_scene_set_tool)", function, scene.source));
  if (def.proxy < -1 || def.proxy > 1)
    return fail(UH_ERROR_INVALID_ARGUMENT,
                fmt::format("{}: def.proxy is {}: -1 (the scene's), 0 (the penalty path) or 1 (the proxy)", function,
                            def.proxy));
  controllers::SessionOptions options;
  if (def.proxy >= 0) options.proxy = def.proxy == 1;
  if (def.haptic_hz != 0.0) options.haptic_hz = def.haptic_hz;
  if (def.collision_hz >= 0.0) options.collision_hz = def.collision_hz;
  options.raise_priority = def.raise_priority != 0;
  options.cache_dir =
      def.cache_dir != nullptr ? std::filesystem::path(def.cache_dir) : controllers::default_cache_dir();
  auto session = controllers::HapticSession::create(scene, options);
  if (!session) return fail(session.error(), UH_ERROR_INVALID_ARGUMENT);
  auto box = std::make_shared<SessionBox>();
  box->session = std::move(session).value();
  for (const auto& o : scene.objects) box->object_names.push_back(o.name);
  for (const auto& t : scene.tools) box->tool_names.push_back(t.name);
  const std::uint64_t id = session_table().insert(std::move(box));
  if (id == 0) return table_full("sessions");
  out->bits = id;
  return UH_OK;
}

// Runs `body(box)` with the session's owner lock held, or fails for a stale handle.
template <typename Body>
uh_status with_session(const char* function, uh_session_id s, Body&& body) {
  return guarded(function, [&]() -> uh_status {
    const auto box = session_table().find(s.bits);
    if (!box) return stale(function, "session");
    const std::lock_guard lock(box->mutex);
    return body(*box);
  });
}

// uh_session_poll and uh_session_tool_state: without the owner lock (HapticSession::state() is
// safe on its own, and the tools are fixed at open)
uh_status poll_tool(const char* fn, uh_session_id s, int32_t tool, uh_state* out) {
  return guarded(fn, [&]() -> uh_status {
    if (auto c = check_out(fn, "out", out); c != UH_OK) return c;
    const auto box = session_table().find(s.bits);
    if (!box) return stale(fn, "session");
    if (tool < 0 || static_cast<std::size_t>(tool) >= box->tool_names.size())
      return fail(UH_ERROR_INVALID_ARGUMENT, fmt::format("{}: there is no tool {} (the scene has {})", fn,
                                                         tool, box->tool_names.size()));
    uh_state state{};
    fill_state(box->session->state(static_cast<std::size_t>(tool)), state);
    write_out(state, out);
    return UH_OK;
  });
}

// uh_session_object_name and uh_session_tool_name: entry `index` of the box's `names`
uh_status name_at(const char* fn, uh_session_id s, std::vector<std::string> SessionBox::*names,
                  const char* kind, int32_t index, const char** out) {
  return with_session(fn, s, [&](SessionBox& box) -> uh_status {
    if (out == nullptr) return null_argument(fn, "out");
    const std::vector<std::string>& list = box.*names;
    if (index < 0 || static_cast<std::size_t>(index) >= list.size())
      return fail(UH_ERROR_INVALID_ARGUMENT,
                  fmt::format("{}: there is no {} {} (the scene has {})", fn, kind, index, list.size()));
    *out = list[static_cast<std::size_t>(index)].c_str();
    return UH_OK;
  });
}

// The uh_session_soft_* functions: `body(box, surface)` for a soft object, with `out` (named
// `out_name`) not NULL.
template <typename Out, typename Body>
uh_status with_soft_surface(const char* fn, uh_session_id s, int32_t object, Out* out, const char* out_name,
                            Body&& body) {
  return with_session(fn, s, [&](SessionBox& box) -> uh_status {
    if (out == nullptr) return null_argument(fn, out_name);
    auto surface = box.session->soft_surface(object < 0 ? box.object_names.size() : static_cast<std::size_t>(object));
    if (!surface) return fail(UH_ERROR_INVALID_ARGUMENT, fmt::format("{}: {}", fn, surface.error().message));
    return body(box, **surface);
  });
}

// a caller's buffer with room for `capacity` items where `needed` are to go
uh_status check_capacity(const char* fn, const char* buffer, const char* items, int32_t capacity, std::size_t needed) {
  if (capacity >= 0 && static_cast<std::size_t>(capacity) >= needed) return UH_OK;
  return fail(UH_ERROR_INVALID_ARGUMENT,
              fmt::format("{}: {} has room for {} {}, the object has {}", fn, buffer, capacity, items, needed));
}

uh_status finish(SessionBox& box, const Status& result) {
  box.stopped = true;
  box.report_json = controllers::session_report_json(box.session->report());
  if (!result) return fail(result.error(), UH_ERROR_THREAD);
  return UH_OK;
}

}  // namespace
}  // namespace uh::capi

using namespace uh;
using namespace uh::capi;

extern "C" {

uh_status uh_session_def_init(uh_session_def* def) { return init_def(__func__, def, default_session_def); }

int32_t uh_session_is_valid(uh_session_id session) { return is_live(session_table(), session.bits); }

uh_status(uh_session_open)(const char* scene_path, uh_session_id* out) {
  return uh_session_open_checked(UH_API_VERSION, scene_path, out);
}

uh_status uh_session_open_checked(int32_t api_version, const char* scene_path, uh_session_id* out) {
  return guarded("uh_session_open", [&]() -> uh_status {
    if (out == nullptr) return null_argument("uh_session_open", "out");
    *out = uh_session_id{0};
    if (auto v = check_version("uh_session_open", api_version); v != UH_OK) return v;
    auto scene = scene_path != nullptr ? controllers::load_scene(scene_path)
                                       : controllers::default_scene(controllers::default_cache_dir());
    if (!scene) return fail(scene.error(), UH_ERROR_FILE);
    return open_session("uh_session_open", *scene, default_session_def(), out);
  });
}

uh_status(uh_session_create)(uh_scene_id scene, const uh_session_def* def, uh_session_id* out) {
  return uh_session_create_checked(UH_API_VERSION, scene, def, out);
}

uh_status uh_session_create_checked(int32_t api_version, uh_scene_id scene, const uh_session_def* def,
                                    uh_session_id* out) {
  return guarded("uh_session_create", [&]() -> uh_status {
    if (out == nullptr) return null_argument("uh_session_create", "out");
    *out = uh_session_id{0};
    if (auto v = check_version("uh_session_create", api_version); v != UH_OK) return v;
    uh_session_def d = default_session_def();
    if (def != nullptr)
      if (auto s = read_def("uh_session_create", "def", def, d); s != UH_OK) return s;
    const auto box = scene_table().find(scene.bits);
    if (!box) return stale("uh_session_create", "scene");
    return open_session("uh_session_create", box->scene, d, out);
  });
}

uh_status uh_session_start(uh_session_id s) {
  const char* const fn = __func__;
  return with_session(fn, s, [&](SessionBox& box) -> uh_status {
    if (box.stopped || box.session->running())
      return fail(UH_ERROR_WRONG_STATE,
                  fmt::format("{}: the session has run already (a session runs once)", fn));
    if (auto started = box.session->start(); !started) return fail(started.error(), UH_ERROR_THREAD);
    return UH_OK;
  });
}

uh_status uh_session_run_stepped(uh_session_id s, double seconds, int32_t ticks_per_collision_step) {
  const char* const fn = __func__;
  return with_session(fn, s, [&](SessionBox& box) -> uh_status {
    if (!(seconds > 0.0 && seconds <= 86400.0) || ticks_per_collision_step < 1)
      return fail(
          UH_ERROR_INVALID_ARGUMENT,
          fmt::format("{}: seconds must be in (0, 86400] and ticks_per_collision_step >= 1 (got {} and {})",
                      fn, seconds, ticks_per_collision_step));
    if (box.stopped || box.session->running())
      return fail(UH_ERROR_WRONG_STATE,
                  fmt::format("{}: the session has run already (a session runs once)", fn));
    return finish(box, box.session->run_stepped(seconds, ticks_per_collision_step));
  });
}

uh_status uh_session_poll(uh_session_id s, uh_state* out) { return poll_tool(__func__, s, 0, out); }

uh_status uh_session_tool_state(uh_session_id s, int32_t tool, uh_state* out) {
  return poll_tool(__func__, s, tool, out);
}

uh_status uh_session_tool_count(uh_session_id s, int32_t* out) {
  const char* const fn = __func__;
  return with_session(fn, s, [&](SessionBox& box) -> uh_status {
    if (out == nullptr) return null_argument(fn, "out");
    *out = static_cast<int32_t>(box.tool_names.size());
    return UH_OK;
  });
}

uh_status uh_session_tool_name(uh_session_id s, int32_t tool, const char** out) {
  return name_at(__func__, s, &SessionBox::tool_names, "tool", tool, out);
}

uh_status uh_session_poll_event(uh_session_id s, uh_contact_event* out, int32_t* has_event) {
  const char* const fn = __func__;
  return with_session(fn, s, [&](SessionBox& box) -> uh_status {
    if (auto c = check_out(fn, "out", out); c != UH_OK) return c;
    if (has_event == nullptr) return null_argument(fn, "has_event");
    controllers::ContactEvent e;
    *has_event = box.session->poll_event(e) ? 1 : 0;
    if (*has_event != 0) {
      uh_contact_event event{};
      event.struct_size = sizeof event;
      event.kind = e.kind == controllers::ContactEventKind::kBegin ? UH_CONTACT_BEGIN : UH_CONTACT_END;
      event.object = e.object;
      event.time_s = e.time_s;
      event.volume = e.volume;
      event.pairs = e.pairs;
      event.tool = e.tool;
      write_out(event, out);
    }
    return UH_OK;
  });
}

uh_status uh_session_set_object_pose(uh_session_id s, int32_t object, const double position[3],
                                     const double orientation[4]) {
  const char* const fn = __func__;
  return with_session(fn, s, [&](SessionBox& box) -> uh_status {
    auto pose = pose_from_arrays(position, orientation);
    if (!pose) return fail(UH_ERROR_INVALID_ARGUMENT, fmt::format("{}: {}", fn, pose.error().message));
    if (auto set = box.session->set_object_pose(object, *pose); !set)
      return fail(UH_ERROR_INVALID_ARGUMENT, fmt::format("{}: {}", fn, set.error().message));
    return UH_OK;
  });
}

uh_status uh_session_set_tick_callback(uh_session_id s, uh_tick_fn callback, void* user) {
  const char* const fn = __func__;
  return with_session(fn, s, [&](SessionBox& box) -> uh_status {
    if (box.stopped || box.session->running())
      return fail(UH_ERROR_WRONG_STATE, fmt::format("{}: only before the session starts", fn));
    box.tick_connection.disconnect();
    box.tick_fn = callback;
    box.tick_user = user;
    if (callback != nullptr)
      box.tick_connection = box.session->on_haptic_tick().connect<&call_tick_callback>(box);
    return UH_OK;
  });
}

uh_status uh_session_ended(uh_session_id s, int32_t* out) {
  const char* const fn = __func__;
  return with_session(fn, s, [&](SessionBox& box) -> uh_status {
    if (out == nullptr) return null_argument(fn, "out");
    *out = box.session->ended_by_itself() ? 1 : 0;
    return UH_OK;
  });
}

uh_status uh_session_stop(uh_session_id s) {
  const char* const fn = __func__;
  return with_session(fn, s, [&](SessionBox& box) -> uh_status {
    if (!box.session->running() && !box.stopped) return UH_OK;  // never started: nothing to stop
    return finish(box, box.session->stop());
  });
}

uh_status uh_session_report_json(uh_session_id s, const char** out) {
  const char* const fn = __func__;
  return with_session(fn, s, [&](SessionBox& box) -> uh_status {
    if (out == nullptr) return null_argument(fn, "out");
    if (!box.stopped)
      return fail(UH_ERROR_WRONG_STATE, fmt::format("{}: the report exists once the session stopped", fn));
    *out = box.report_json.c_str();
    return UH_OK;
  });
}

uh_status uh_session_object_count(uh_session_id s, int32_t* out) {
  const char* const fn = __func__;
  return with_session(fn, s, [&](SessionBox& box) -> uh_status {
    if (out == nullptr) return null_argument(fn, "out");
    *out = static_cast<int32_t>(box.object_names.size());
    return UH_OK;
  });
}

uh_status uh_session_object_name(uh_session_id s, int32_t object, const char** out) {
  return name_at(__func__, s, &SessionBox::object_names, "object", object, out);
}

uh_status uh_session_soft_vertex_count(uh_session_id s, int32_t object, int32_t* out) {
  const char* const fn = __func__;
  return with_soft_surface(fn, s, object, out, "out", [&](SessionBox&, const soft::SurfaceMesh& surface) -> uh_status {
    *out = static_cast<int32_t>(surface.vertices.size());
    return UH_OK;
  });
}

uh_status uh_session_soft_vertices(uh_session_id s, int32_t object, float* xyz, int32_t capacity, uint64_t* step) {
  const char* const fn = __func__;
  return with_soft_surface(fn, s, object, xyz, "xyz", [&](SessionBox& box, const soft::SurfaceMesh& surface) -> uh_status {
    if (auto c = check_capacity(fn, "xyz", "vertices", capacity, surface.vertices.size()); c != UH_OK) return c;
    auto made = box.session->soft_vertices(static_cast<std::size_t>(object),
                                           std::span<float>(xyz, 3 * static_cast<std::size_t>(capacity)));
    if (!made) return fail(made.error(), UH_ERROR_INVALID_ARGUMENT);
    if (step != nullptr) *step = *made;
    return UH_OK;
  });
}

uh_status uh_session_soft_triangle_count(uh_session_id s, int32_t object, int32_t* out) {
  const char* const fn = __func__;
  return with_soft_surface(fn, s, object, out, "out", [&](SessionBox&, const soft::SurfaceMesh& surface) -> uh_status {
    *out = static_cast<int32_t>(surface.triangles.size());
    return UH_OK;
  });
}

uh_status uh_session_soft_triangles(uh_session_id s, int32_t object, int32_t* indices, int32_t capacity) {
  const char* const fn = __func__;
  return with_soft_surface(fn, s, object, indices, "indices", [&](SessionBox&, const soft::SurfaceMesh& surface) -> uh_status {
    if (auto c = check_capacity(fn, "indices", "triangles", capacity, surface.triangles.size()); c != UH_OK) return c;
    for (std::size_t t = 0; t < surface.triangles.size(); ++t)
      for (std::size_t k = 0; k < 3; ++k) indices[3 * t + k] = surface.triangles[t][k];
    return UH_OK;
  });
}

void uh_session_destroy(uh_session_id s) {
  const char* const fn = __func__;
  const uh_status ignored = guarded(fn, [&]() -> uh_status {
    const auto box = session_table().remove(s.bits);
    if (!box) return UH_OK;
    const std::lock_guard lock(box->mutex);
    const Status stopped = box->session->stop();
    (void)stopped;  // closing: nobody is left to tell
    return UH_OK;
  });
  (void)ignored;
}

}  // extern "C"
