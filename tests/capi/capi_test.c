/* Tests of the C API, written in C99 as a user of uh.h would. One program; argv[1] names the
 * test (each is its own ctest). Paths: UH_TEST_DATA_DIR (the committed meshes). */
#define _POSIX_C_SOURCE 199309L /* nanosleep */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "uh/uh.h"
#include "uh_v2_0_structs.h" /* an older caller's structs: API version 2's first layouts */

static int failures = 0;

#define CHECK(cond)                                                                              \
  do {                                                                                           \
    if (!(cond)) {                                                                               \
      fprintf(stderr, "%s:%d: CHECK failed: %s (last error: %s)\n", __FILE__, __LINE__, #cond, \
              uh_last_error());                                                                  \
      ++failures;                                                                                \
    }                                                                                            \
  } while (0)

#define CHECK_STATUS(call, expected)                                                               \
  do {                                                                                             \
    const uh_status status_ = (call);                                                              \
    if (status_ != (expected)) {                                                                   \
      fprintf(stderr, "%s:%d: %s returned %s, expected %s (last error: %s)\n", __FILE__, __LINE__, \
              #call, uh_status_name(status_), uh_status_name(expected), uh_last_error());          \
      ++failures;                                                                                  \
    }                                                                                              \
  } while (0)

#define REQUIRE_OK(call)                                                                          \
  do {                                                                                            \
    const uh_status status_ = (call);                                                             \
    if (status_ != UH_OK) {                                                                       \
      fprintf(stderr, "%s:%d: %s returned %s: %s\n", __FILE__, __LINE__, #call,                   \
              uh_status_name(status_), uh_last_error());                                          \
      exit(1);                                                                                    \
    }                                                                                             \
  } while (0)

static void sleep_ms(long ms) {
  struct timespec t;
  t.tv_sec = ms / 1000;
  t.tv_nsec = (ms % 1000) * 1000000L;
  nanosleep(&t, NULL);
}

static double norm3(const double v[3]) { return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

/* The number after "key": in the report JSON, after `section` (enough for this report's layout). */
static double json_number(const char* json, const char* section, const char* key) {
  const char* at = strstr(json, section);
  char pattern[64];
  if (at == NULL) return NAN;
  snprintf(pattern, sizeof pattern, "\"%s\":", key);
  at = strstr(at, pattern);
  return at != NULL ? strtod(at + strlen(pattern), NULL) : NAN;
}

static uh_shape_def mesh_shape(const char* file, int64_t spheres) {
  static char paths[4][512];
  static int next = 0;
  uh_shape_def shape = uh_default_shape_def();
  char* path = paths[next++ % 4];
  snprintf(path, 512, "%s/meshes/%s", UH_TEST_DATA_DIR, file);
  shape.mesh_path = path;
  shape.spheres = spheres;
  shape.meters_per_unit = 0.01;
  return shape;
}

/* The small scene of the C++ session tests, built through calls: a 10 cm bunny (600 spheres) and
 * a stylus (150) that goes down into it and back every second (sim-line). */
static uh_scene_id small_scene(void) {
  uh_scene_id scene = {0};
  uh_object_def bunny = uh_default_object_def();
  uh_tool_def tool = uh_default_tool_def();
  REQUIRE_OK(uh_scene_create("small-c", &scene));
  bunny.name = "bunny";
  bunny.shape = mesh_shape("bunny_npm_3674.obj", 600);
  bunny.orientation[0] = 0.70710678;
  bunny.orientation[1] = 0.70710678;
  REQUIRE_OK(uh_scene_add_object(scene, &bunny, NULL));
  tool.name = "stylus";
  tool.shape = mesh_shape("stylus.obj", 150);
  tool.stiffness = 1.6e4;
  tool.damping = 1.0;
  tool.center_of_mass[2] = 0.025;
  tool.max_force_n = 6.0;
  tool.max_torque_nm = 0.3;
  tool.device_driver = "sim-line";
  tool.device_config_json =
      "{\"start\": [0, 0, 0.10], \"end\": [0, 0, 0.045], \"duration_s\": 0.5, \"bounce\": true,"
      " \"dof_actuated\": 6, \"max_force_n\": 6}";
  CHECK(tool.law == UH_FORCE_LAW_GRADIENT); /* the default law */
  tool.law = 7;
  CHECK_STATUS(uh_scene_set_tool(scene, &tool), UH_ERROR_INVALID_ARGUMENT);
  tool.law = UH_FORCE_LAW_GRADIENT;
  tool.stiffness = -1.0;
  CHECK_STATUS(uh_scene_set_tool(scene, &tool), UH_ERROR_INVALID_ARGUMENT);
  tool.stiffness = 1.6e4;
  REQUIRE_OK(uh_scene_set_tool(scene, &tool));
  return scene;
}

static uh_session_id open_small_session(void) {
  uh_scene_id scene = small_scene();
  uh_session_id s = {0};
  REQUIRE_OK(uh_session_create(scene, NULL, &s));
  uh_scene_destroy(scene); /* the session copied it */
  return s;
}

/* what the tick callback saw (stepped: on this thread) */
typedef struct {
  uint64_t ticks;
  double max_force;
  int32_t max_pairs;
} tick_record;

static void record_tick(void* user, const uh_state* state) {
  tick_record* r = (tick_record*)user;
  const double f = norm3(state->force);
  ++r->ticks;
  if (f > r->max_force) r->max_force = f;
  if (state->contact_pairs > r->max_pairs) r->max_pairs = state->contact_pairs;
}

static void test_version(void) {
  uh_session_id s = {1};
  /* the library reports the project's version, project(VERSION) in the top-level CMakeLists.txt */
  CHECK(strcmp(uh_version_string(), UH_TEST_PROJECT_VERSION) == 0);
  CHECK(uh_api_version() == UH_API_VERSION);
  CHECK_STATUS(uh_session_open_checked(UH_API_VERSION + 1, NULL, &s), UH_ERROR_VERSION);
  CHECK(s.bits == 0);
  CHECK(strstr(uh_last_error(), "UH_API_VERSION") != NULL);
  CHECK(strcmp(uh_status_name(UH_ERROR_STALE_HANDLE), "UH_ERROR_STALE_HANDLE") == 0);
}

/* The default scene (the bunny sweep) run deterministically: contact and force read back. */
static void test_default_session_stepped(void) {
  uh_session_id s = {0};
  uh_state st;
  uh_contact_event e;
  tick_record rec = {0, 0.0, 0};
  int32_t has_event = 0, begins = 0;
  const char* report = NULL;
  REQUIRE_OK(uh_session_open(NULL, &s));
  REQUIRE_OK(uh_session_set_tick_callback(s, record_tick, &rec));
  /* bad arguments are refused before anything runs, in the caller's terms (no C++ names) */
  CHECK(uh_session_run_stepped(s, -1.0, 4) != UH_OK);
  CHECK(strstr(uh_last_error(), "uh_session_run_stepped: seconds must be in (0, 86400]") != NULL);
  CHECK(strstr(uh_last_error(), "::") == NULL);
  CHECK(uh_session_run_stepped(s, 1.0, 0) != UH_OK);
  CHECK(strstr(uh_last_error(), "(got 1 and 0)") != NULL);
  REQUIRE_OK(uh_session_run_stepped(s, 3.0, 4));
  memset(&st, 0, sizeof st);
  st.struct_size = sizeof st;
  REQUIRE_OK(uh_session_poll(s, &st));
  CHECK(st.haptic_ticks == 3000);
  /* the callback saw the 3000 ticks and then the zero force the run ended with (not a tick) */
  CHECK(rec.ticks == 3001);
  CHECK(norm3(st.force) == 0.0);
  CHECK(fabs(st.time_s - 3.0) < 1e-9); /* the zero is sent one period after the last tick (2.999 s) */
  CHECK(rec.max_force > 0.5); /* the sweep goes into deep contact */
  CHECK(rec.max_force <= 8.0 + 1e-9);
  CHECK(rec.max_pairs > 0);
  e.struct_size = sizeof e;
  while (uh_session_poll_event(s, &e, &has_event) == UH_OK && has_event) {
    CHECK(e.object == 0);
    if (e.kind == UH_CONTACT_BEGIN) {
      ++begins;
      /* through the proxy, the default, which rests on the surface: rows in contact, no overlap */
      CHECK(e.volume == 0.0 && e.pairs > 0);
    }
  }
  CHECK(begins >= 1);
  REQUIRE_OK(uh_session_report_json(s, &report));
  /* two paths to the same figure: the states the callback saw, the controller's own maximum */
  CHECK(fabs(json_number(report, "\"force\"", "max_n") - rec.max_force) < 1e-9);
  CHECK(json_number(report, "\"haptic\"", "ticks") == 3000.0);
  CHECK(strstr(report, "\"mode\": \"stepped\"") != NULL);
  REQUIRE_OK(uh_session_stop(s)); /* stopped already: idempotent */
  uh_session_destroy(s);
}

/* A short threaded run of a scene built through calls: poll state and events while it runs. */
static void test_threaded_session(void) {
  uh_session_id s = open_small_session();
  uh_state st;
  uh_contact_event e;
  int32_t has_event = 0, begins = 0, i, ended = 1;
  double max_force = 0.0;
  int32_t max_pairs = 0;
  uint64_t last_ticks = 0;
  const char* report = NULL;
  st.struct_size = sizeof st;
  e.struct_size = sizeof e;
  REQUIRE_OK(uh_session_start(s));
  CHECK_STATUS(uh_session_start(s), UH_ERROR_WRONG_STATE);
  CHECK_STATUS(uh_session_set_tick_callback(s, record_tick, NULL), UH_ERROR_WRONG_STATE);
  for (i = 0; i < 600; ++i) { /* about 1.2 s */
    REQUIRE_OK(uh_session_ended(s, &ended));
    CHECK(ended == 0); /* nothing faults here */
    REQUIRE_OK(uh_session_poll(s, &st));
    CHECK(st.haptic_ticks >= last_ticks);
    last_ticks = st.haptic_ticks;
    if (norm3(st.force) > max_force) max_force = norm3(st.force);
    if (st.contact_pairs > max_pairs) max_pairs = st.contact_pairs;
    CHECK(st.buttons == 0); /* the scene's scripted device presses none */
    while (uh_session_poll_event(s, &e, &has_event) == UH_OK && has_event) begins += e.kind == UH_CONTACT_BEGIN;
    sleep_ms(2);
  }
  REQUIRE_OK(uh_session_stop(s));
  ended = 1;
  REQUIRE_OK(uh_session_ended(s, &ended));
  CHECK(ended == 0); /* stopped, not ended by itself */
  REQUIRE_OK(uh_session_poll(s, &st));
  CHECK(norm3(st.force) == 0.0); /* the device got zero at stop */
  CHECK(last_ticks > 300);       /* ~1200 at 1 kHz; loose for sanitizer builds */
  CHECK(max_force > 0.1);
  CHECK(max_force <= 6.0 + 1e-9);
  CHECK(max_pairs > 0);
  CHECK(begins >= 1);
  REQUIRE_OK(uh_session_report_json(s, &report));
  CHECK(strstr(report, "\"mode\": \"threaded\"") != NULL);
  CHECK(json_number(report, "\"force\"", "max_n") >= max_force - 1e-9);
  uh_session_destroy(s);
}

/* Two sessions at once, each with its own threads and device. */
static void test_several_sessions(void) {
  uh_session_id a = open_small_session();
  uh_session_id b = open_small_session();
  uh_state sa, sb;
  int i;
  double max_a = 0.0, max_b = 0.0;
  sa.struct_size = sizeof sa;
  sb.struct_size = sizeof sb;
  REQUIRE_OK(uh_session_start(a));
  REQUIRE_OK(uh_session_start(b));
  for (i = 0; i < 400; ++i) {
    REQUIRE_OK(uh_session_poll(a, &sa));
    REQUIRE_OK(uh_session_poll(b, &sb));
    if (norm3(sa.force) > max_a) max_a = norm3(sa.force);
    if (norm3(sb.force) > max_b) max_b = norm3(sb.force);
    sleep_ms(2);
  }
  REQUIRE_OK(uh_session_stop(a));
  CHECK(uh_session_poll(b, &sb) == UH_OK && sb.haptic_ticks > 0); /* b runs on after a stopped */
  uh_session_destroy(b);                                             /* close stops b */
  uh_session_destroy(a);
  CHECK(max_a > 0.1);
  CHECK(max_b > 0.1);

  /* stepped sessions of the same scene are bit-for-bit equal */
  a = open_small_session();
  b = open_small_session();
  REQUIRE_OK(uh_session_run_stepped(a, 0.5, 4));
  REQUIRE_OK(uh_session_run_stepped(b, 0.5, 4));
  REQUIRE_OK(uh_session_poll(a, &sa));
  REQUIRE_OK(uh_session_poll(b, &sb));
  CHECK(memcmp(sa.force, sb.force, sizeof sa.force) == 0);
  CHECK(memcmp(sa.tool_position, sb.tool_position, sizeof sa.tool_position) == 0);
  CHECK(norm3(sa.force) == 0.0); /* a run ends with zero force sent */
  uh_session_destroy(a);
  uh_session_destroy(b);
}

/* Misuse gives statuses, never crashes. */
static void test_handle_misuse(void) {
  uh_session_id s = open_small_session();
  uh_session_id stale_handle = s;
  const uh_session_id none = {0};
  uh_state st;
  uh_contact_event e;
  int32_t has_event = 0, count = 0;
  const char* text = NULL;
  uh_tree_id tree = {0};
  st.struct_size = sizeof st;
  e.struct_size = sizeof e;

  CHECK_STATUS(uh_session_report_json(s, &text), UH_ERROR_WRONG_STATE); /* before it ran */
  CHECK_STATUS(uh_session_stop(s), UH_OK);                              /* before start: nothing to do */
  CHECK_STATUS(uh_session_poll(s, &st), UH_OK);
  CHECK(st.haptic_ticks == 0);
  st.struct_size = 8;
  CHECK_STATUS(uh_session_poll(s, &st), UH_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(uh_last_error(), "uh_session_poll: out->struct_size is 8") != NULL); /* names the call */
  st.struct_size = sizeof st;
  CHECK_STATUS(uh_session_poll(s, NULL), UH_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(uh_session_poll_event(s, &e, NULL), UH_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(uh_session_ended(s, NULL), UH_ERROR_INVALID_ARGUMENT);
  count = 1;
  CHECK_STATUS(uh_session_ended(s, &count), UH_OK);
  CHECK(count == 0); /* before start */
  CHECK_STATUS(uh_session_object_name(s, 7, &text), UH_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(uh_session_object_name(s, 0, &text), UH_OK);
  CHECK(text != NULL && strcmp(text, "bunny") == 0);
  {
    const double p[3] = {0, 0, 0}, zero_q[4] = {0, 0, 0, 0}, nan_p[3] = {NAN, 0, 0}, q[4] = {1, 0, 0, 0};
    CHECK_STATUS(uh_session_set_object_pose(s, 0, p, zero_q), UH_ERROR_INVALID_ARGUMENT);
    CHECK_STATUS(uh_session_set_object_pose(s, 0, nan_p, q), UH_ERROR_INVALID_ARGUMENT);
    CHECK_STATUS(uh_session_set_object_pose(s, 3, p, q), UH_ERROR_INVALID_ARGUMENT);
  }

  REQUIRE_OK(uh_session_start(s));
  REQUIRE_OK(uh_session_stop(s));
  CHECK_STATUS(uh_session_stop(s), UH_OK); /* twice */
  CHECK_STATUS(uh_session_start(s), UH_ERROR_WRONG_STATE);
  CHECK_STATUS(uh_session_run_stepped(s, 0.1, 4), UH_ERROR_WRONG_STATE);
  CHECK_STATUS(uh_session_report_json(s, &text), UH_OK);
  uh_session_destroy(s);
  uh_session_destroy(s); /* twice: nothing */
  uh_session_destroy(none);

  CHECK_STATUS(uh_session_poll(stale_handle, &st), UH_ERROR_STALE_HANDLE);
  CHECK(strstr(uh_last_error(), "uh_session_poll: the session id") != NULL);
  CHECK_STATUS(uh_session_start(stale_handle), UH_ERROR_STALE_HANDLE);
  CHECK_STATUS(uh_session_stop(stale_handle), UH_ERROR_STALE_HANDLE);
  CHECK_STATUS(uh_session_poll_event(stale_handle, &e, &has_event), UH_ERROR_STALE_HANDLE);
  CHECK_STATUS(uh_session_object_count(stale_handle, &count), UH_ERROR_STALE_HANDLE);
  CHECK_STATUS(uh_session_ended(stale_handle, &count), UH_ERROR_STALE_HANDLE);
  CHECK_STATUS(uh_session_start(none), UH_ERROR_STALE_HANDLE);
  {
    const uh_session_id made_up = {0xdeadbeef0ull};
    CHECK_STATUS(uh_session_poll(made_up, &st), UH_ERROR_STALE_HANDLE);
    CHECK(!uh_session_is_valid(made_up) && !uh_session_is_valid(none));
  }
  CHECK(!uh_session_is_valid(stale_handle));

  /* a new session may reuse the slot: the old handle still refers to nothing */
  s = open_small_session();
  CHECK(s.bits != stale_handle.bits && uh_session_is_valid(s));
  CHECK_STATUS(uh_session_poll(stale_handle, &st), UH_ERROR_STALE_HANDLE);
  CHECK_STATUS(uh_session_poll(s, &st), UH_OK);
  /* a handle of another kind is refused */
  CHECK_STATUS(uh_tree_load("/nonexistent.ist", &tree), UH_ERROR_FILE);
  CHECK(tree.bits == 0);
  CHECK(strstr(uh_last_error(), "/nonexistent.ist") != NULL);
  {
    const uh_tree_id session_as_tree = {s.bits};
    uh_tree_info info;
    CHECK_STATUS(uh_tree_get_info(session_as_tree, NULL), UH_ERROR_INVALID_ARGUMENT);
    info.struct_size = sizeof info;
    CHECK_STATUS(uh_tree_get_info(session_as_tree, &info), UH_ERROR_STALE_HANDLE);
    CHECK(!uh_tree_is_valid(session_as_tree));
  }
  uh_session_destroy(s);
  CHECK_STATUS(uh_session_open(NULL, NULL), UH_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(uh_session_open("/nonexistent/scene.json", &s), UH_ERROR_FILE);
  CHECK(s.bits == 0);
  CHECK(strstr(uh_last_error(), "/nonexistent/scene.json") != NULL);
}

/* Sessions stopped the moment they started, many times: the threads' stop must never miss the
 * request however early it comes (under mingw-w64's libstdc++ a stop wait could hang, once in
 * about a hundred runs under wine: uh/core/address_wait.hpp). */
static void test_start_stop_at_once(void) {
  int i;
  for (i = 0; i < 150; ++i) {
    uh_session_id s = open_small_session();
    REQUIRE_OK(uh_session_start(s));
    CHECK_STATUS(uh_session_stop(s), UH_OK);
    uh_session_destroy(s);
  }
}

/* A closed cube of side 2 cm centred on the origin, as arrays (outward, counter-clockwise). */
static const double cube_vertices[8 * 3] = {-1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1,
                                            -1, -1, 1,  1, -1, 1,  1, 1, 1,  -1, 1, 1};
static const int32_t cube_indices[12 * 3] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                             1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};

/* The format version of a .ist file (the u32 at byte 8), or -1. */
static int ist_format_of(const char* path) {
  unsigned char header[12];
  FILE* f = fopen(path, "rb");
  size_t got;
  if (f == NULL) return -1;
  got = fread(header, 1, sizeof header, f);
  fclose(f);
  return got == sizeof header ? header[8] | header[9] << 8 | header[10] << 16 | header[11] << 24 : -1;
}

/* Trees from arrays, queried: against itself at the identity every leaf meets itself and no other
 * (the packing does not overlap), so the volume is the packing's own, known from the build. */
static void test_trees(void) {
  uh_tree_build_def def = uh_default_tree_build_def();
  uh_tree_id a = {0}, b = {0}, loaded = {0};
  uh_tree_info info;
  uh_query_result r;
  const double origin[3] = {0, 0, 0}, identity[4] = {1, 0, 0, 0}, far[3] = {0.1, 0, 0};
  const double shifted[3] = {0.005, 0, 0}, scaled_identity[4] = {3, 0, 0, 0};
  char path[512];
  def.spheres = 400;
  def.meters_per_unit = 0.01;
  REQUIRE_OK(uh_tree_build_from_arrays(cube_vertices, 8, cube_indices, 12, &def, &a));
  info.struct_size = sizeof info;
  REQUIRE_OK(uh_tree_get_info(a, &info));
  CHECK(info.leaf_count > 100);
  CHECK(fabs(info.mesh_volume - 8e-6) < 1e-12); /* (2 cm)^3 */
  CHECK(info.coverage > 0.3 && info.coverage < 1.0);
  CHECK(info.radius > 0.005 && info.radius < 0.02);

  snprintf(path, sizeof path, "%s/capi_cube_test.ist", UH_TEST_TMP_DIR);
  REQUIRE_OK(uh_tree_save(a, path));
  /* the tree keeps the mesh it was built from, and a loaded tree the surface its file holds: both
   * are saved with it (format 2), so a session's proxy rests on the cube, not on the spheres */
  CHECK(ist_format_of(path) == 2);
  REQUIRE_OK(uh_tree_load(path, &b));
  remove(path);
  REQUIRE_OK(uh_tree_save(b, path));
  CHECK(ist_format_of(path) == 2);
  remove(path);

  r.struct_size = sizeof r;
  REQUIRE_OK(uh_tree_query(a, b, origin, identity, &r));
  CHECK(fabs(r.volume - info.coverage * info.mesh_volume) < 1e-4 * r.volume);
  CHECK(fabs(r.volume_estimate - info.mesh_volume / info.coverage) < 1e-4 * r.volume_estimate);
  CHECK(r.pair_count >= info.leaf_count);
  CHECK(r.distance == 0.0);
  /* B moved 5 mm along +x: it is pushed out along +x */
  REQUIRE_OK(uh_tree_query(a, b, shifted, scaled_identity, &r));
  CHECK(r.volume > 0.0 && r.direction[0] > 0.9);
  /* apart: no volume, a separation */
  REQUIRE_OK(uh_tree_query(a, b, far, identity, &r));
  CHECK(r.volume == 0.0 && r.pair_count == 0);
  CHECK(r.distance > 0.07 && r.distance < 0.1);

  /* bad input (a failed build leaves its out id zero) */
  loaded = b;
  CHECK_STATUS(uh_tree_build_from_arrays(cube_vertices, 8, cube_indices, 10, &def, &b), UH_ERROR_MESH);
  CHECK(b.bits == 0);
  CHECK(strstr(uh_last_error(), "not closed") != NULL);
  def.spheres = 0;
  CHECK_STATUS(uh_tree_build_from_arrays(cube_vertices, 8, cube_indices, 12, &def, &b), UH_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(uh_last_error(), "sphere count must be positive") != NULL);
  {
    const uh_tree_id none = {0};
    CHECK_STATUS(uh_tree_query(a, none, origin, identity, &r), UH_ERROR_STALE_HANDLE);
  }
  {
    const double zero_q[4] = {0, 0, 0, 0};
    CHECK_STATUS(uh_tree_query(a, a, origin, zero_q, &r), UH_ERROR_INVALID_ARGUMENT);
  }
  CHECK(uh_tree_is_valid(loaded));
  uh_tree_destroy(loaded);
  CHECK(!uh_tree_is_valid(loaded));
  CHECK_STATUS(uh_tree_query(a, loaded, origin, identity, &r), UH_ERROR_STALE_HANDLE);
  uh_tree_destroy(loaded); /* twice: nothing */
  uh_tree_destroy(a);
}

/* Scenes through calls: objects from a tree, removal, watch, device config errors. */
static void test_scene_building(void) {
  uh_scene_id scene = small_scene();
  uh_object_def cube = uh_default_object_def();
  uh_tool_def tool = uh_default_tool_def();
  uh_tree_build_def def = uh_default_tree_build_def();
  uh_tree_id tree = {0};
  uh_session_id s = {0};
  int32_t count = 0, index = -1;
  const char* name = NULL;
  def.spheres = 200;
  def.meters_per_unit = 0.01;
  REQUIRE_OK(uh_tree_build_from_arrays(cube_vertices, 8, cube_indices, 12, &def, &tree));
  cube.name = "cube";
  cube.shape.tree = tree;
  cube.position[0] = 0.2; /* beside the bunny, never touched */
  REQUIRE_OK(uh_scene_add_object(scene, &cube, &index));
  CHECK(index == 1);
  uh_tree_destroy(tree); /* the scene keeps its own reference */
  CHECK_STATUS(uh_scene_add_object(scene, &cube, NULL), UH_ERROR_INVALID_ARGUMENT); /* duplicate name */
  cube.name = "two sources";
  cube.shape = mesh_shape("stylus.obj", 100);
  cube.shape.ist_path = "x.ist";
  CHECK_STATUS(uh_scene_add_object(scene, &cube, NULL), UH_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(uh_last_error(), "exactly one") != NULL);
  cube.shape = mesh_shape("missing.obj", 100);
  CHECK_STATUS(uh_scene_add_object(scene, &cube, NULL), UH_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(uh_last_error(), "missing.obj") != NULL);
  REQUIRE_OK(uh_scene_object_count(scene, &count));
  CHECK(count == 2);

  REQUIRE_OK(uh_session_create(scene, NULL, &s));
  REQUIRE_OK(uh_session_object_count(s, &count));
  CHECK(count == 2);
  REQUIRE_OK(uh_session_object_name(s, 1, &name));
  CHECK(strcmp(name, "cube") == 0);
  REQUIRE_OK(uh_session_run_stepped(s, 0.5, 4));
  uh_session_destroy(s);

  CHECK_STATUS(uh_scene_remove_object(scene, "nothing"), UH_ERROR_INVALID_ARGUMENT);
  REQUIRE_OK(uh_scene_remove_object(scene, "cube"));
  REQUIRE_OK(uh_scene_object_count(scene, &count));
  CHECK(count == 1);
  REQUIRE_OK(uh_scene_watch(scene, "bunny", 0));
  REQUIRE_OK(uh_session_create(scene, NULL, &s));
  CHECK_STATUS(uh_session_start(s), UH_ERROR_INVALID_ARGUMENT); /* nothing watched */
  CHECK(strstr(uh_last_error(), "nothing is watched") != NULL);
  uh_session_destroy(s);
  REQUIRE_OK(uh_scene_watch(scene, "bunny", 1));

  tool.shape = mesh_shape("stylus.obj", 150);
  tool.device_config_json = "{\"start\": {\"x\": 1}}";
  CHECK_STATUS(uh_scene_set_tool(scene, &tool), UH_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(uh_last_error(), "start") != NULL);
  tool.device_config_json = "{not json";
  CHECK_STATUS(uh_scene_set_tool(scene, &tool), UH_ERROR_INVALID_ARGUMENT);
  tool.device_config_json = NULL;
  tool.device_driver = "phantom-omni";
  REQUIRE_OK(uh_scene_set_tool(scene, &tool));
  CHECK_STATUS(uh_session_create(scene, NULL, &s), UH_ERROR_DEVICE);
  CHECK(strstr(uh_last_error(), "phantom-omni") != NULL);
  CHECK_STATUS(uh_scene_set_rates(scene, 0.5, 100), UH_ERROR_INVALID_ARGUMENT);
  uh_scene_destroy(scene);
  uh_scene_destroy(scene);
  CHECK_STATUS(uh_scene_object_count(scene, &count), UH_ERROR_STALE_HANDLE);
  CHECK(!uh_scene_is_valid(scene));

  REQUIRE_OK(uh_scene_create("empty", &scene));
  CHECK_STATUS(uh_session_create(scene, NULL, &s), UH_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(uh_last_error(), "no tool") != NULL);
  uh_scene_destroy(scene);
}

/* The cube above written as OBJ (quads, corners with normals), binary STL, ASCII STL and OFF. */
static void write_cube_files(const char* dir) {
  static const int quads[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                  {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  char path[512];
  FILE* f;
  int i, k, t;
  snprintf(path, sizeof path, "%s/capi_cube.obj", dir);
  f = fopen(path, "w");
  fprintf(f, "# a cube\no cube\n");
  for (i = 0; i < 8; ++i)
    fprintf(f, "v %g %g %g\n", cube_vertices[3 * i], cube_vertices[3 * i + 1], cube_vertices[3 * i + 2]);
  fprintf(f, "vn 0 0 1\n");
  for (i = 0; i < 6; ++i)
    fprintf(f, "f %d//1 %d//1 %d//1 %d//1\n", quads[i][0] + 1, quads[i][1] + 1, quads[i][2] + 1,
            quads[i][3] + 1);
  fclose(f);

  snprintf(path, sizeof path, "%s/capi_cube_binary.stl", dir);
  f = fopen(path, "wb");
  {
    char header[80];
    const uint32_t count = 12;
    memset(header, ' ', sizeof header);
    memcpy(header, "solid cube", 10); /* binary, although it begins like an ASCII file */
    fwrite(header, 1, sizeof header, f);
    fwrite(&count, 4, 1, f); /* little-endian, as the format is, on the machines this runs on */
    for (t = 0; t < 12; ++t) {
      float v[12] = {0};
      const uint16_t attribute = 0;
      for (k = 0; k < 3; ++k) {
        for (i = 0; i < 3; ++i) v[3 + 3 * k + i] = (float)cube_vertices[3 * cube_indices[3 * t + k] + i];
      }
      fwrite(v, sizeof v, 1, f);
      fwrite(&attribute, 2, 1, f);
    }
  }
  fclose(f);

  snprintf(path, sizeof path, "%s/capi_cube_ascii.stl", dir);
  f = fopen(path, "w");
  fprintf(f, "solid cube\n");
  for (t = 0; t < 12; ++t) {
    fprintf(f, "  facet normal 0 0 0\n    outer loop\n");
    for (k = 0; k < 3; ++k) {
      const double* v = &cube_vertices[3 * cube_indices[3 * t + k]];
      fprintf(f, "      vertex %g %g %g\n", v[0], v[1], v[2]);
    }
    fprintf(f, "    endloop\n  endfacet\n");
  }
  fprintf(f, "endsolid cube\n");
  fclose(f);

  snprintf(path, sizeof path, "%s/capi_cube.off", dir);
  f = fopen(path, "w");
  fprintf(f, "OFF\n8 12 0\n");
  for (i = 0; i < 8; ++i)
    fprintf(f, "%g %g %g\n", cube_vertices[3 * i], cube_vertices[3 * i + 1], cube_vertices[3 * i + 2]);
  for (t = 0; t < 12; ++t)
    fprintf(f, "3 %d %d %d\n", cube_indices[3 * t], cube_indices[3 * t + 1], cube_indices[3 * t + 2]);
  fclose(f);
}

/* Trees from mesh files: OBJ and STL (binary and ASCII) everywhere, OFF where the library reads
 * meshes through assimp (Linux); the Windows build reads OBJ and STL only and says so. */
static void test_mesh_formats(void) {
  static const char* files[] = {"capi_cube.obj", "capi_cube_binary.stl", "capi_cube_ascii.stl",
                                "capi_cube.off"};
  uh_tree_build_def def = uh_default_tree_build_def();
  char path[512];
  size_t i;
  def.spheres = 200;
  def.meters_per_unit = 0.01;
  write_cube_files(UH_TEST_TMP_DIR);
  for (i = 0; i < sizeof files / sizeof files[0]; ++i) {
    uh_tree_id tree = {0};
    uh_tree_info info;
    uh_status status;
    snprintf(path, sizeof path, "%s/%s", UH_TEST_TMP_DIR, files[i]);
    status = uh_tree_build(path, &def, &tree);
#ifdef _WIN32
    if (strstr(files[i], ".off") != NULL) {
      CHECK(status == UH_ERROR_FILE && tree.bits == 0);
      CHECK(strstr(uh_last_error(), "capi_cube.off") != NULL);
      CHECK(strstr(uh_last_error(), "OBJ (.obj) and STL (.stl) files only") != NULL);
      remove(path);
      continue;
    }
#endif
    if (status != UH_OK) {
      fprintf(stderr, "%s: %s\n", files[i], uh_last_error());
      ++failures;
      remove(path);
      continue;
    }
    info.struct_size = sizeof info;
    REQUIRE_OK(uh_tree_get_info(tree, &info));
    CHECK(fabs(info.mesh_volume - 8e-6) < 1e-12); /* (2 cm)^3, whatever the file format */
    CHECK(info.leaf_count > 50);
    uh_tree_destroy(tree);
    remove(path);
  }
}

/* A scene file with two tools, each on its own simulated device (the left stylus presses into
 * the bunny, the right one into a ball): each tool's state through uh_session_tool_state, the
 * first also through uh_session_poll, and each tool in the report. */
static void test_two_tools(void) {
  char path[512];
  FILE* f;
  uh_session_id s = {0};
  int32_t count = 0;
  const char* name = NULL;
  const char* report = NULL;
  uh_state first = {0}, left = {0}, right = {0};
  snprintf(path, sizeof path, "%s/capi_two_tools.json", UH_TEST_TMP_DIR);
  f = fopen(path, "w");
  if (f == NULL) {
    fprintf(stderr, "cannot write %s\n", path);
    exit(1);
  }
  fprintf(
      f,
      "{\"name\": \"two-c\", \"objects\": ["
      "{\"name\": \"bunny\", \"mesh\": \"%s/meshes/bunny_npm_3674.obj\", \"meters_per_unit\": 0.01,"
      " \"spheres\": 600, \"pose\": {\"rotation\": [0.70710678, 0.70710678, 0, 0]}},"
      "{\"name\": \"ball\", \"mesh\": \"%s/meshes/ball.obj\", \"meters_per_unit\": 0.03, \"spheres\": 200,"
      " \"pose\": {\"position\": [0.15, 0, 0.03]}}],"
      " \"tools\": ["
      "{\"name\": \"left\", \"mesh\": \"%s/meshes/stylus.obj\", \"meters_per_unit\": 0.01, \"spheres\": 150,"
      " \"force\": {\"mode\": \"3dof\", \"stiffness\": 1.6e4, \"max_force_n\": 6.0},"
      " \"device\": {\"driver\": \"sim-line\", \"config\": {\"start\": [0, 0, 0.1], \"end\": [0, 0, "
      "0.045]}}},"
      "{\"name\": \"right\", \"mesh\": \"%s/meshes/stylus.obj\", \"meters_per_unit\": 0.01, \"spheres\": 150,"
      " \"force\": {\"mode\": \"3dof\", \"stiffness\": 1.6e4, \"max_force_n\": 4.0},"
      " \"device\": {\"driver\": \"sim-line\", \"config\": {\"start\": [0.15, 0, 0.1], \"end\": [0.15, 0, "
      "0.048]}}}"
      "]}",
      UH_TEST_DATA_DIR, UH_TEST_DATA_DIR, UH_TEST_DATA_DIR, UH_TEST_DATA_DIR);
  fclose(f);
  REQUIRE_OK(uh_session_open(path, &s));
  REQUIRE_OK(uh_session_tool_count(s, &count));
  CHECK(count == 2);
  REQUIRE_OK(uh_session_tool_name(s, 1, &name));
  CHECK(strcmp(name, "right") == 0);
  CHECK_STATUS(uh_session_tool_name(s, 2, &name), UH_ERROR_INVALID_ARGUMENT);
  REQUIRE_OK(uh_session_run_stepped(s, 1.0, 4));
  first.struct_size = left.struct_size = right.struct_size = sizeof(uh_state);
  REQUIRE_OK(uh_session_poll(s, &first));
  REQUIRE_OK(uh_session_tool_state(s, 0, &left));
  REQUIRE_OK(uh_session_tool_state(s, 1, &right));
  /* uh_session_poll is the first tool's */
  CHECK(first.haptic_ticks == left.haptic_ticks && first.time_s == left.time_s);
  CHECK(first.tool_position[0] == left.tool_position[0] && first.tool_position[2] == left.tool_position[2]);
  CHECK(right.haptic_ticks == 1000);
  CHECK(fabs(right.handle_position[0] - 0.15) < 1e-9 && fabs(left.handle_position[0]) < 1e-9);
  CHECK_STATUS(uh_session_tool_state(s, 2, &right), UH_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(uh_last_error(), "uh_session_tool_state: there is no tool 2 (the scene has 2)") != NULL);
  CHECK_STATUS(uh_session_tool_state(s, -1, &right), UH_ERROR_INVALID_ARGUMENT);
  REQUIRE_OK(uh_session_report_json(s, &report));
  CHECK(strstr(report, "\"tool\": \"right\"") != NULL);
  uh_session_destroy(s);
  remove(path);
}

/* The small scene's stylus as the older caller (uh_v2_0_structs.h) sets it: its own smaller
 * struct_size, the fields it knows, defaults from uh_tool_def_init written only as far as its end. */
static void old_stylus(uh_v2_0_tool_def* tool) {
  const uh_shape_def shape = mesh_shape("stylus.obj", 150);
  memset(tool, 0, sizeof *tool);
  tool->struct_size = (uint32_t)sizeof *tool;
  REQUIRE_OK(uh_tool_def_init((uh_tool_def*)tool));
  tool->name = "stylus";
  memcpy(&tool->shape, &shape, sizeof tool->shape);
  tool->stiffness = 1.6e4;
  tool->damping = 1.0;
  tool->center_of_mass[2] = 0.025;
  tool->max_force_n = 6.0;
  tool->max_torque_nm = 0.3;
  tool->device_config_json =
      "{\"start\": [0, 0, 0.10], \"end\": [0, 0, 0.045], \"duration_s\": 0.5, \"bounce\": true,"
      " \"dof_actuated\": 6, \"max_force_n\": 6}";
}

/* The small scene (bunny, stylus) with the tool given as `tool` (any layout), run stepped for
 * 0.5 s: the final state and the report's largest force. */
static double run_with_tool(const void* tool, uh_state* final_state) {
  uh_scene_id scene = {0};
  uh_session_id s = {0};
  uh_object_def bunny = uh_default_object_def();
  const char* report = NULL;
  double max_force;
  REQUIRE_OK(uh_scene_create("tool-layouts", &scene));
  bunny.name = "bunny";
  bunny.shape = mesh_shape("bunny_npm_3674.obj", 600);
  bunny.orientation[0] = 0.70710678;
  bunny.orientation[1] = 0.70710678;
  REQUIRE_OK(uh_scene_add_object(scene, &bunny, NULL));
  REQUIRE_OK(uh_scene_set_tool(scene, (const uh_tool_def*)tool));
  REQUIRE_OK(uh_session_create(scene, NULL, &s));
  uh_scene_destroy(scene);
  REQUIRE_OK(uh_session_run_stepped(s, 0.5, 4));
  final_state->struct_size = sizeof *final_state;
  REQUIRE_OK(uh_session_poll(s, final_state));
  REQUIRE_OK(uh_session_report_json(s, &report));
  max_force = json_number(report, "\"force\"", "max_n");
  uh_session_destroy(s);
  return max_force;
}

/* A program built against API version 2's first uh.h (its structs frozen in uh_v2_0_structs.h,
 * smaller than today's where a struct grew) against this library: its structs are accepted, the
 * fields they lack take their defaults, and nothing is read or written past their end. */
static void test_older_caller(void) {
  struct {
    uh_v2_0_tool_def def;
    unsigned char after[64]; /* where a newer layout's fields would be */
  } old_tool;
  struct {
    uh_v2_0_state state;
    unsigned char after[64];
  } old_state;
  uh_v2_0_object_def old_bunny;
  uh_v2_0_session_def old_session;
  uh_v2_0_contact_event old_event;
  uh_tool_def new_tool = uh_default_tool_def();
  uh_scene_id scene = {0};
  uh_session_id s = {0};
  uh_state old_run, new_run, offset_run;
  double old_force, new_force, offset_force;
  int32_t has_event = 0, events = 0;
  size_t i;
  const uh_shape_def bunny_shape = mesh_shape("bunny_npm_3674.obj", 600);

  CHECK(sizeof old_tool.def < sizeof(uh_tool_def)); /* the tool def grew since */
  /* defaults reach only as far as the caller's struct */
  memset(&old_tool, 0xab, sizeof old_tool);
  old_tool.def.struct_size = (uint32_t)sizeof old_tool.def;
  REQUIRE_OK(uh_tool_def_init((uh_tool_def*)&old_tool.def));
  for (i = 0; i < sizeof old_tool.after; ++i) CHECK(old_tool.after[i] == 0xab);
  CHECK(old_tool.def.struct_size == sizeof old_tool.def);
  CHECK(old_tool.def.stiffness == new_tool.stiffness && old_tool.def.max_force_n == new_tool.max_force_n);
  CHECK(strcmp(old_tool.def.name, "tool") == 0 && old_tool.def.workspace_rotation[0] == 1.0);
  CHECK(old_tool.def.shape.spheres == new_tool.shape.spheres);

  /* the stylus set through the old layout, with bytes past its end that would be a NaN offset if
   * they were read, runs as the same stylus through today's layout with tool_offset at its default */
  old_stylus(&old_tool.def);
  memset(old_tool.after, 0xff, sizeof old_tool.after);
  old_force = run_with_tool(&old_tool.def, &old_run);
  memcpy(&new_tool, &old_tool.def, sizeof old_tool.def);
  new_tool.struct_size = sizeof new_tool;
  CHECK(new_tool.tool_offset[0] == 0.0 && new_tool.tool_offset[1] == 0.0 && new_tool.tool_offset[2] == 0.0);
  new_force = run_with_tool(&new_tool, &new_run);
  CHECK(old_force > 0.5 && old_force == new_force);
  CHECK(memcmp(old_run.tool_position, new_run.tool_position, sizeof old_run.tool_position) == 0);
  CHECK(old_run.haptic_ticks == 500 && new_run.haptic_ticks == 500);
  /* and the new field is read when the layout has it: the handle puts the stylus 1 cm lower */
  new_tool.tool_offset[2] = -0.01;
  offset_force = run_with_tool(&new_tool, &offset_run);
  CHECK(fabs(offset_run.handle_position[2] - (new_run.handle_position[2] - 0.01)) < 1e-9);
  CHECK(offset_force != new_force);

  /* a whole flow in old structs: object, tool, session settings, state and events */
  REQUIRE_OK(uh_scene_create("older-caller", &scene));
  memset(&old_bunny, 0, sizeof old_bunny);
  old_bunny.struct_size = (uint32_t)sizeof old_bunny;
  REQUIRE_OK(uh_object_def_init((uh_object_def*)&old_bunny));
  CHECK(old_bunny.watch == 1 && old_bunny.orientation[0] == 1.0);
  old_bunny.name = "bunny";
  memcpy(&old_bunny.shape, &bunny_shape, sizeof old_bunny.shape);
  old_bunny.orientation[0] = 0.70710678;
  old_bunny.orientation[1] = 0.70710678;
  REQUIRE_OK(uh_scene_add_object(scene, (const uh_object_def*)&old_bunny, NULL));
  REQUIRE_OK(uh_scene_set_tool(scene, (const uh_tool_def*)&old_tool.def));
  memset(&old_session, 0, sizeof old_session);
  old_session.struct_size = (uint32_t)sizeof old_session;
  REQUIRE_OK(uh_session_def_init((uh_session_def*)&old_session));
  CHECK(old_session.collision_hz == -1.0);
  REQUIRE_OK(uh_session_create(scene, (const uh_session_def*)&old_session, &s));
  uh_scene_destroy(scene);
  REQUIRE_OK(uh_session_run_stepped(s, 0.5, 4));
  memset(&old_state, 0xab, sizeof old_state);
  old_state.state.struct_size = (uint32_t)sizeof old_state.state;
  REQUIRE_OK(uh_session_poll(s, (uh_state*)&old_state.state));
  for (i = 0; i < sizeof old_state.after; ++i) CHECK(old_state.after[i] == 0xab);
  CHECK(old_state.state.haptic_ticks == 500);
  CHECK(memcmp(old_state.state.tool_position, old_run.tool_position, sizeof old_run.tool_position) == 0);
  old_event.struct_size = (uint32_t)sizeof old_event;
  while (uh_session_poll_event(s, (uh_contact_event*)&old_event, &has_event) == UH_OK && has_event) {
    CHECK(old_event.object == 0 && old_event.struct_size == sizeof old_event);
    ++events;
  }
  CHECK(events >= 1);

  /* a newer program's struct than this library knows is refused, saying so */
  new_tool.struct_size = (uint32_t)sizeof new_tool + 8;
  REQUIRE_OK(uh_scene_create("newer-caller", &scene));
  CHECK_STATUS(uh_scene_set_tool(scene, &new_tool), UH_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(uh_last_error(), "newer uh.h") != NULL);
  new_tool.struct_size = (uint32_t)sizeof old_tool.def - 8; /* no layout at all */
  CHECK_STATUS(uh_scene_set_tool(scene, &new_tool), UH_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(uh_last_error(), "no layout of uh_tool_def") != NULL);
  uh_scene_destroy(scene);
  uh_session_destroy(s);
}

/* The session def chooses how contact is rendered: the penalty path leaves the tool at the handle
 * (inside the bunny at the press's deepest), the proxy keeps it on the surface above the handle
 * (the state's handle_position says where the handle is); an unknown choice is refused by name. */
static void test_proxy_choice(void) {
  uh_scene_id scene = small_scene();
  uh_session_id s = {0};
  uh_session_def def = uh_default_session_def();
  uh_state state;
  const char* report = NULL;
  int32_t proxy;
  CHECK(def.proxy == -1); /* the scene's */
  for (proxy = 0; proxy <= 1; ++proxy) {
    def.proxy = proxy;
    REQUIRE_OK(uh_session_create(scene, &def, &s));
    REQUIRE_OK(uh_session_run_stepped(s, 0.5, 4));
    memset(&state, 0, sizeof state);
    state.struct_size = (uint32_t)sizeof state;
    REQUIRE_OK(uh_session_poll(s, &state));
    CHECK(fabs(state.handle_position[2] - 0.045) < 1e-3); /* the press's deepest */
    if (proxy == 0) {
      CHECK(memcmp(state.tool_position, state.handle_position, sizeof state.tool_position) == 0);
    } else {
      CHECK(state.tool_position[2] > state.handle_position[2] + 0.001); /* held on the surface */
    }
    REQUIRE_OK(uh_session_report_json(s, &report));
    CHECK(json_number(report, "\"force\"", "max_n") > 0.5); /* pushed back, either way */
    uh_session_destroy(s);
  }
  def.proxy = 2;
  CHECK_STATUS(uh_session_create(scene, &def, &s), UH_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(uh_last_error(), "def.proxy is 2") != NULL);
  uh_scene_destroy(scene);
}

/* scenes/soft_block.json's block read through the C API: at rest, then pressed by its ball in a
 * stepped run, the vertices of its top under the ball have gone down; a rigid object and a short
 * buffer are refused with messages that say why. */
static void test_soft_vertices(void) {
  uh_session_id s = {0};
  uh_scene_id scene = small_scene();
  uh_session_def def = uh_default_session_def();
  int32_t vertices = 0, triangles = 0, i, under = 0;
  uint64_t step = 99;
  float *rest, *pressed;
  int32_t* indices;
  double deepest = 0.0;
  REQUIRE_OK(uh_session_open(UH_TEST_SCENES_DIR "/soft_block.json", &s));
  REQUIRE_OK(uh_session_soft_vertex_count(s, 0, &vertices));
  REQUIRE_OK(uh_session_soft_triangle_count(s, 0, &triangles));
  CHECK(vertices > 1000 && triangles > 2000); /* the 12 triangles of block.obj, refined */
  rest = malloc(sizeof(float) * 3 * (size_t)vertices);
  pressed = malloc(sizeof(float) * 3 * (size_t)vertices);
  indices = malloc(sizeof(int32_t) * 3 * (size_t)triangles);
  REQUIRE_OK(uh_session_soft_triangles(s, 0, indices, triangles));
  for (i = 0; i < 3 * triangles; ++i) CHECK(indices[i] >= 0 && indices[i] < vertices);
  REQUIRE_OK(uh_session_soft_vertices(s, 0, rest, vertices, &step));
  CHECK(step == 0);
  CHECK_STATUS(uh_session_soft_vertices(s, 0, pressed, vertices - 1, NULL), UH_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(uh_last_error(), "xyz has room for") != NULL);
  CHECK_STATUS(uh_session_soft_vertices(s, 0, NULL, vertices, NULL), UH_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(uh_session_soft_vertex_count(s, 1, &i), UH_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(uh_last_error(), "no scene object 1") != NULL);

  REQUIRE_OK(uh_session_run_stepped(s, 1.0, 1)); /* the ball 6 mm into the block's top */
  REQUIRE_OK(uh_session_soft_vertices(s, 0, pressed, vertices, &step));
  CHECK(step >= 90); /* 100 Hz steps */
  for (i = 0; i < vertices; ++i) {
    const float* r = rest + 3 * i;
    const double drop = (double)r[2] - (double)pressed[3 * i + 2];
    if (fabs((double)r[2]) < 1e-6 && sqrt((double)(r[0] * r[0] + r[1] * r[1])) < 0.004) {
      ++under;
      if (drop > deepest) deepest = drop;
    }
  }
  printf("soft block: %d vertices, %d triangles; %d top vertices under the ball, deepest drop %.3f mm\n",
         vertices, triangles, under, deepest * 1e3);
  CHECK(under > 0);
  CHECK(deepest > 5e-4);
  uh_session_destroy(s);

  REQUIRE_OK(uh_session_create(scene, &def, &s));
  CHECK_STATUS(uh_session_soft_vertex_count(s, 0, &i), UH_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(uh_last_error(), "is rigid") != NULL);
  uh_session_destroy(s);
  uh_scene_destroy(scene);
  free(rest);
  free(pressed);
  free(indices);
}

/* Two tools added through calls, each on its own device: the left stylus presses into the bunny,
 * the right one into a ball; each contact event names its tool. */
static void test_several_tools(void) {
  uh_scene_id scene = small_scene();
  uh_object_def ball = uh_default_object_def();
  uh_tool_def right = uh_default_tool_def();
  uh_session_id s = {0};
  uh_contact_event e;
  uh_state left_state, right_state;
  int32_t count = 0, index = -1, has_event = 0, begins[2] = {0, 0};
  const char* name = NULL;
  ball.name = "ball";
  ball.shape = mesh_shape("ball.obj", 200);
  ball.shape.meters_per_unit = 0.03;
  ball.position[0] = 0.15;
  ball.position[2] = 0.03;
  REQUIRE_OK(uh_scene_add_object(scene, &ball, NULL));
  right.name = "stylus"; /* the first tool's name */
  right.shape = mesh_shape("stylus.obj", 150);
  right.mode = UH_FORCE_3DOF;
  right.stiffness = 1.6e4;
  right.max_force_n = 4.0;
  right.device_config_json = "{\"start\": [0.15, 0, 0.1], \"end\": [0.15, 0, 0.048]}";
  CHECK_STATUS(uh_scene_add_tool(scene, &right, NULL), UH_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(uh_last_error(), "a tool named 'stylus' already") != NULL);
  right.name = "right";
  REQUIRE_OK(uh_scene_add_tool(scene, &right, &index));
  CHECK(index == 1);
  REQUIRE_OK(uh_scene_tool_count(scene, &count));
  CHECK(count == 2);
  REQUIRE_OK(uh_session_create(scene, NULL, &s));
  REQUIRE_OK(uh_session_tool_count(s, &count));
  CHECK(count == 2);
  REQUIRE_OK(uh_session_tool_name(s, 1, &name));
  CHECK(strcmp(name, "right") == 0);
  REQUIRE_OK(uh_session_run_stepped(s, 1.0, 4));
  left_state.struct_size = right_state.struct_size = sizeof(uh_state);
  REQUIRE_OK(uh_session_tool_state(s, 0, &left_state));
  REQUIRE_OK(uh_session_tool_state(s, 1, &right_state));
  CHECK(fabs(right_state.handle_position[0] - 0.15) < 1e-9 && fabs(left_state.handle_position[0]) < 1e-9);
  e.struct_size = sizeof e;
  while (uh_session_poll_event(s, &e, &has_event) == UH_OK && has_event) {
    CHECK(e.tool == 0 || e.tool == 1);
    CHECK(e.object == e.tool); /* the left stylus meets the bunny only, the right one the ball */
    if (e.kind == UH_CONTACT_BEGIN && e.tool >= 0 && e.tool < 2) ++begins[e.tool];
  }
  CHECK(begins[0] >= 1 && begins[1] >= 1);
  uh_session_destroy(s);

  /* tools removed by name; a scene without one cannot open */
  CHECK_STATUS(uh_scene_remove_tool(scene, "nobody"), UH_ERROR_INVALID_ARGUMENT);
  REQUIRE_OK(uh_scene_remove_tool(scene, "stylus"));
  REQUIRE_OK(uh_scene_remove_tool(scene, "right"));
  REQUIRE_OK(uh_scene_tool_count(scene, &count));
  CHECK(count == 0);
  CHECK_STATUS(uh_session_create(scene, NULL, &s), UH_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(uh_last_error(), "no tool") != NULL);
  REQUIRE_OK(uh_scene_set_tool(scene, &right)); /* set_tool on a scene without tools adds the first */
  REQUIRE_OK(uh_scene_tool_count(scene, &count));
  CHECK(count == 1);
  uh_scene_destroy(scene);
}

int main(int argc, char** argv) {
  static const struct {
    const char* name;
    void (*run)(void);
  } tests[] = {{"version", test_version},
               {"default_session_stepped", test_default_session_stepped},
               {"threaded_session", test_threaded_session},
               {"several_sessions", test_several_sessions},
               {"handle_misuse", test_handle_misuse},
               {"start_stop_at_once", test_start_stop_at_once},
               {"trees", test_trees},
               {"scene_building", test_scene_building},
               {"mesh_formats", test_mesh_formats},
               {"two_tools", test_two_tools},
               {"older_caller", test_older_caller},
               {"several_tools", test_several_tools},
               {"proxy_choice", test_proxy_choice},
               {"soft_vertices", test_soft_vertices}};
  size_t i;
  if (argc != 2) {
    fprintf(stderr, "usage: %s TEST\n", argv[0]);
    return 2;
  }
  for (i = 0; i < sizeof tests / sizeof tests[0]; ++i) {
    if (strcmp(argv[1], tests[i].name) == 0) {
      tests[i].run();
      printf("%s: %s (%d failed checks)\n", tests[i].name, failures == 0 ? "passed" : "FAILED", failures);
      return failures == 0 ? 0 : 1;
    }
  }
  fprintf(stderr, "unknown test '%s'\n", argv[1]);
  return 2;
}
