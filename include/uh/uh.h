/*
 * uh.h: the UnrealHaptics C API (plain C99, library libuh, CMake target uh::capi).
 *
 * One header for engines (Unreal, Unity's P/Invoke, Godot), other languages and plain C programs:
 * open a haptic session (a scene: objects, tools each bound to a device, watched objects), start its
 * haptic and collision threads, poll its newest state and its contact events, stop it; and query
 * Inner Sphere Trees directly.
 *
 * Rules that hold for every function:
 *  - Every call that can fail returns a uh_status; UH_OK (0) is success, each failure has its own
 *    status (a file, a mesh, a device, a thread, ...). After a failure, uh_last_error() returns a
 *    message for the calling thread that names what was wrong (a file, a field, an id). No C++
 *    exception ever leaves the library.
 *  - Objects are ids passed by value (uh_tree_id, uh_scene_id, uh_session_id; after Box2D v3): a
 *    fixed-width integer holding a slot index, the slot's generation and the kind, never an
 *    address. A destroyed or made-up id is refused with UH_ERROR_STALE_HANDLE, not a crash;
 *    uh_*_is_valid() tells whether an id is live. Destroying a zero or stale id does nothing.
 *  - Structs that cross the boundary start with `struct_size`: set it to sizeof(the struct) (the
 *    uh_default_*() functions do). Structs only grow, at their end: a program built against an
 *    older uh.h of this UH_API_VERSION passes its smaller struct_size, the library reads the fields
 *    that struct has and takes the defaults for the rest, and writes into it only the fields it
 *    has. A struct_size this library does not know (a newer header's, or a wrong one) is refused
 *    with UH_ERROR_INVALID_ARGUMENT. docs/capi.md states the promise.
 *  - There is no global state a call depends on: any number of sessions, scenes and trees may
 *    exist in one process; each call names the one it works on.
 *  - Units are SI: metres, seconds, newtons; quaternions are (w, x, y, z), unit length.
 *  - Threads: see each section. In short: a session's calls may come from any thread and are
 *    serialised per session; only uh_session_poll() runs alongside them. Callbacks marked
 *    "haptic thread" are real-time: no allocation, no locks, no blocking, no calls into this API.
 */
#ifndef UH_UH_H
#define UH_UH_H

#include <stddef.h>
#include <stdint.h>

/* The API version this header describes. Raised on every incompatible change (a function renamed
 * or removed, a field moved); a program built against one version is refused at open by a library
 * of another (UH_ERROR_VERSION). Growing a struct at its end or adding a function or a status is
 * compatible and keeps the version. */
#define UH_API_VERSION 2

#if defined(_WIN32) || defined(__CYGWIN__)
#if defined(UH_CAPI_BUILDING)
#define UH_API __declspec(dllexport)
#else
#define UH_API __declspec(dllimport)
#endif
#elif defined(__GNUC__)
#define UH_API __attribute__((visibility("default")))
#else
#define UH_API
#endif

#include <string.h> /* memset, for the uh_default_*() inline functions */

#ifdef __cplusplus
extern "C" {
#endif

/* ---------------------------------------------------------------------------------------------
 * Status, errors, version
 * ------------------------------------------------------------------------------------------- */

/* What a call did (a fixed-size integer; the values below). */
typedef int32_t uh_status;
enum {
  UH_OK = 0,                      /* success */
  UH_ERROR_INVALID_ARGUMENT = 1,  /* NULL where a value is needed, a number out of range, a bad struct_size,
                                     a scene that cannot run (no tool, nothing watched) */
  UH_ERROR_STALE_HANDLE = 2,      /* the id was destroyed, never made, or is an id of another kind */
  UH_ERROR_WRONG_STATE = 3,       /* not possible now: start twice, start after stop, a callback set while running */
  UH_ERROR_VERSION = 4,           /* the program was compiled against another UH_API_VERSION */
  /* 5 was API version 1's UH_ERROR_FAILED; never returned */
  UH_ERROR_INTERNAL = 6,          /* an unexpected failure inside the library (out of memory, a bug) */
  UH_ERROR_FILE = 7,              /* a file could not be found, read or written, or its content is wrong
                                     (a damaged .ist, a scene file's field, a mesh format the build does not read) */
  UH_ERROR_MESH = 8,              /* a mesh cannot be used: open, non-manifold, degenerate, no volume, not packable */
  UH_ERROR_DEVICE = 9,            /* a device: unknown driver, bad settings, would not open, faulted while running */
  UH_ERROR_THREAD = 10,           /* a haptic or collision thread could not start, or ended on its own */
  UH_ERROR_BUSY = 11              /* in use or full: a device another tool holds, too many ids of a kind open */
};

/* The library's version, e.g. "0.1.0". Static storage; any thread. */
UH_API const char* uh_version_string(void);

/* The UH_API_VERSION the library was built with. Any thread. */
UH_API int32_t uh_api_version(void);

/* The message of the calling thread's last failed call ("" if none). Valid until the next failing
 * call on this thread. Any thread. */
UH_API const char* uh_last_error(void);

/* A short name of a status ("UH_OK", "UH_ERROR_STALE_HANDLE", ...). Static storage. */
UH_API const char* uh_status_name(uh_status status);

/* ---------------------------------------------------------------------------------------------
 * Ids and defaults
 *
 * An id is a value: copy it, compare its `bits`, keep it in any struct; zero is no id. Every
 * descriptor struct has a uh_X_init(def) that fills the fields that fit in def->struct_size with
 * their defaults (set struct_size first), and a uh_default_X() inline function below that does
 * both, compiled into the caller with the caller's uh.h, so that an older program's smaller
 * struct is never written past its end.
 * ------------------------------------------------------------------------------------------- */

typedef struct uh_tree_id { uint64_t bits; } uh_tree_id;       /* an Inner Sphere Tree */
typedef struct uh_scene_id { uint64_t bits; } uh_scene_id;     /* a scene description */
typedef struct uh_session_id { uint64_t bits; } uh_session_id; /* a session (a scene running) */

/* 1 while the id refers to a live object of its kind, 0 once destroyed, for zero or a made-up id
 * (generation-checked: a stale id is never dereferenced). Any thread. */
UH_API int32_t uh_tree_is_valid(uh_tree_id tree);
UH_API int32_t uh_scene_is_valid(uh_scene_id scene);
UH_API int32_t uh_session_is_valid(uh_session_id session);

/* ---------------------------------------------------------------------------------------------
 * Inner Sphere Trees: load, build, query
 *
 * A tree is immutable once made; it may be queried from several threads at once and shared with
 * scenes (a scene keeps its own reference, so the tree may be destroyed after adding it). Lengths
 * are metres: a .ist's meters_per_unit is applied on load, the build settings' on build.
 * ------------------------------------------------------------------------------------------- */

/* How to pack a mesh with spheres. */
typedef struct uh_tree_build_def {
  uint32_t struct_size;    /* sizeof(uh_tree_build_def) */
  int64_t spheres;         /* target number of leaf spheres, > 0 (default 10000) */
  double meters_per_unit;  /* length of one mesh unit [m], > 0 (default 1) */
} uh_tree_build_def;

UH_API uh_status uh_tree_build_def_init(uh_tree_build_def* def);
static inline uh_tree_build_def uh_default_tree_build_def(void) {
  uh_tree_build_def def;
  memset(&def, 0, sizeof def);
  def.struct_size = (uint32_t)sizeof def;
  (void)uh_tree_build_def_init(&def);
  return def;
}

/* Loads a .ist file (checksummed; a damaged file is refused with the reason: UH_ERROR_FILE). The
 * surface a format 2 file holds comes with the tree: a session's proxy rests on it. */
UH_API uh_status uh_tree_load(const char* ist_path, uh_tree_id* out);

/* Loads a closed mesh (OBJ, STL, PLY, OFF, ...; the Windows build reads OBJ and STL only),
 * validates it (an open or non-manifold mesh is refused with the counts of bad edges:
 * UH_ERROR_MESH), packs it and builds the tree. Takes about a second per 10,000 spheres. `def`
 * may be NULL (defaults). */
UH_API uh_status uh_tree_build(const char* mesh_path, const uh_tree_build_def* def, uh_tree_id* out);

/* Same from arrays: `vertices` holds vertex_count * 3 coordinates (x, y, z, in mesh units),
 * `indices` triangle_count * 3 vertex indices, counter-clockwise seen from outside. The arrays
 * are copied; the mesh must be closed and manifold. */
UH_API uh_status uh_tree_build_from_arrays(const double* vertices, int32_t vertex_count, const int32_t* indices,
                                           int32_t triangle_count, const uh_tree_build_def* def, uh_tree_id* out);

/* Writes the tree as a .ist file (lengths in metres, meters_per_unit 1), with the surface it was
 * built from or loaded with (format 2; format 1 without one). */
UH_API uh_status uh_tree_save(uh_tree_id tree, const char* ist_path);

/* What a tree holds. */
typedef struct uh_tree_info {
  uint32_t struct_size;   /* sizeof(uh_tree_info) */
  int32_t leaf_count;     /* leaf spheres */
  double coverage;        /* sphere volume / mesh volume, 0..1 (0 if unknown) */
  double mesh_volume;     /* volume of the mesh [m^3] (0 if unknown) */
  double center[3];       /* bounding sphere of the root [m, tree frame] */
  double radius;          /* [m] */
} uh_tree_info;

UH_API uh_status uh_tree_get_info(uh_tree_id tree, uh_tree_info* out);

/* Destroys the tree (scenes that hold it keep their reference). Zero or a stale id: nothing. */
UH_API void uh_tree_destroy(uh_tree_id tree);

/* The overlap of two trees at one pose. */
typedef struct uh_query_result {
  uint32_t struct_size;     /* sizeof(uh_query_result) */
  double volume;            /* intersection volume of the two packings [m^3], >= 0 */
  double volume_estimate;   /* volume / (coverage_a * coverage_b): an estimate of the meshes' overlap [m^3] */
  double direction[3];      /* unit, A's frame: the direction of the force the gradient law puts on B
                               (minus the gradient of the packings' overlap volume); zero when apart */
  int32_t pair_count;       /* overlapping leaf sphere pairs */
  double distance;          /* separation when apart (an upper bound) [m]; 0 when they overlap */
} uh_query_result;

/* Queries B placed at (position, orientation) in A's frame against A. Any thread; a thread's
 * first query allocates its scratch (about 2 MB), later ones do not. */
UH_API uh_status uh_tree_query(uh_tree_id a, uh_tree_id b, const double position[3], const double orientation[4],
                               uh_query_result* out);

/* ---------------------------------------------------------------------------------------------
 * Scenes: what a session runs, from a file or built through calls
 *
 * A scene is a description (objects, tools and their devices, watched objects, rates); sessions
 * copy it when they open, so it may be changed or destroyed afterwards. One thread at a time.
 * ------------------------------------------------------------------------------------------- */

/* Where a shape's tree comes from: exactly one of mesh_path, ist_path, tree or the arrays. It is
 * embedded in uh_object_def and uh_tool_def, so it never grows (new shape settings go at the end
 * of those). */
typedef struct uh_shape_def {
  uint32_t struct_size;      /* sizeof(uh_shape_def) */
  const char* mesh_path;     /* a closed mesh, packed on first use and cached (see uh_session_def.cache_dir) */
  const char* ist_path;      /* a .ist file */
  uh_tree_id tree;           /* a tree made by uh_tree_load/uh_tree_build (shared, not copied); zero: none */
  const double* vertices;    /* or a closed mesh as arrays (see uh_tree_build_from_arrays) */
  int32_t vertex_count;
  const int32_t* indices;
  int32_t triangle_count;
  int64_t spheres;           /* leaf spheres when packing a mesh (default 10000) */
  double meters_per_unit;    /* length of one mesh unit [m] (default 1) */
} uh_shape_def;

/* A static object of the scene. */
typedef struct uh_object_def {
  uint32_t struct_size;      /* sizeof(uh_object_def) */
  const char* name;          /* unique in the scene; copied */
  uh_shape_def shape;
  double position[3];        /* world_from_object [m] */
  double orientation[4];     /* (w, x, y, z) */
  int32_t watch;             /* nonzero (default): every tool is watched against this object */
} uh_object_def;

/* How forces are rendered on the tool. */
typedef int32_t uh_force_mode;
enum { UH_FORCE_6DOF = 0, UH_FORCE_3DOF = 1 };

/* Which force law (docs/forcecomp.md). GRADIENT: minus the gradient of the overlap volume, calibrated
 * by the packings' coverages, stiffness k [N/m^2] (force per unit of contact area). PAPER: the
 * UnrealHaptics paper's eq. 1, force_scale eps_c [N/m^3] (force per overlap volume). */
typedef int32_t uh_force_law;
enum { UH_FORCE_LAW_GRADIENT = 0, UH_FORCE_LAW_PAPER = 1 };

/* A tool: a shape moved by its own device, with its force law and limits. */
typedef struct uh_tool_def {
  uint32_t struct_size;        /* sizeof(uh_tool_def) */
  const char* name;            /* unique among the scene's tools; default "tool" */
  uh_shape_def shape;
  uh_force_mode mode;          /* default UH_FORCE_6DOF */
  uh_force_law law;            /* default UH_FORCE_LAW_GRADIENT */
  double stiffness;   /* gradient law: k [N/m^2]; a round tip of radius r is a spring of 2 pi r k N/m */
  double force_scale; /* paper law: eps_c [N/m^3] */
  double damping;              /* eps_d [N s/m] */
  double damping_full_volume;  /* overlap volume from which the full damping acts [m^3] (default 2e-8; 0: from
                                  the first touch) */
  double mass_kg;              /* tool mass [kg] */
  double center_of_mass[3];    /* [m, tool frame] */
  double max_force_n;          /* limit of the tool's force [N] */
  double max_torque_nm;        /* limit of its torque [N m] */
  const char* device_driver;   /* a registered driver: "sim-line", "sim-circle", "sim-raster", "sim-replay", "sim-hand" */
  const char* device_config_json; /* the driver's settings as a JSON object (numbers, strings, booleans, [x,y,z]); NULL = {} */
  double workspace_scale;      /* world metres per device metre (default 1) */
  double workspace_offset[3];  /* the device base in the world [m] */
  double workspace_rotation[4];/* (w, x, y, z) */
  /* --- added in API version 2's second layout (older callers get the default) --- */
  double tool_offset[3];       /* the tool's mesh origin in the device handle's frame [m] (a scene file's
                                  workspace.tool_offset; default 0) */
} uh_tool_def;

UH_API uh_status uh_shape_def_init(uh_shape_def* def);
UH_API uh_status uh_object_def_init(uh_object_def* def);
UH_API uh_status uh_tool_def_init(uh_tool_def* def);
static inline uh_shape_def uh_default_shape_def(void) {
  uh_shape_def def;
  memset(&def, 0, sizeof def);
  def.struct_size = (uint32_t)sizeof def;
  (void)uh_shape_def_init(&def);
  return def;
}
static inline uh_object_def uh_default_object_def(void) {
  uh_object_def def;
  memset(&def, 0, sizeof def);
  def.struct_size = (uint32_t)sizeof def;
  (void)uh_object_def_init(&def);
  return def;
}
static inline uh_tool_def uh_default_tool_def(void) {
  uh_tool_def def;
  memset(&def, 0, sizeof def);
  def.struct_size = (uint32_t)sizeof def;
  (void)uh_tool_def_init(&def);
  return def;
}

/* An empty scene (no objects, no tool yet; rates 1 kHz haptic and collision). */
UH_API uh_status uh_scene_create(const char* name, uh_scene_id* out);
/* A scene file (docs/pipeline.md); NULL: the embedded default scene. */
UH_API uh_status uh_scene_load(const char* scene_path, uh_scene_id* out);
/* Scene JSON text; relative paths resolve against base_dir (NULL: the current folder). */
UH_API uh_status uh_scene_parse(const char* json_text, const char* base_dir, uh_scene_id* out);
/* Destroys the scene. Zero or a stale id: nothing. */
UH_API void uh_scene_destroy(uh_scene_id scene);

/* Adds an object; `out_index` (may be NULL) gets its index, which sessions use for it. The
 * shape's files must exist now (the tree is loaded or built when a session opens). */
UH_API uh_status uh_scene_add_object(uh_scene_id scene, const uh_object_def* def, int32_t* out_index);
/* Removes the object named `name`; later objects move down one index. */
UH_API uh_status uh_scene_remove_object(uh_scene_id scene, const char* name);
/* Sets the pose of the object named `name`. */
UH_API uh_status uh_scene_set_object_pose(uh_scene_id scene, const char* name, const double position[3],
                                          const double orientation[4]);
/* Watches the object named `name` against every tool, or stops watching it. */
UH_API uh_status uh_scene_watch(uh_scene_id scene, const char* name, int32_t watch);
/* Sets the first tool (the only one of a one-tool scene; added when the scene has none). The
 * device config is checked when a session opens. */
UH_API uh_status uh_scene_set_tool(uh_scene_id scene, const uh_tool_def* def);
/* Adds a tool after the scene's tools, each on its own device and haptic thread (two hands, two
 * users); `out_index` (may be NULL) gets its index, which sessions use for it. Tools pass through
 * each other. */
UH_API uh_status uh_scene_add_tool(uh_scene_id scene, const uh_tool_def* def, int32_t* out_index);
/* Removes the tool named `name`; later tools move down one index. */
UH_API uh_status uh_scene_remove_tool(uh_scene_id scene, const char* name);
UH_API uh_status uh_scene_tool_count(uh_scene_id scene, int32_t* out);
/* Haptic rate in [1, 10000] Hz; collision rate in [0, 10000] Hz (0 = free-running). */
UH_API uh_status uh_scene_set_rates(uh_scene_id scene, double haptic_hz, double collision_hz);
UH_API uh_status uh_scene_object_count(uh_scene_id scene, int32_t* out);

/* ---------------------------------------------------------------------------------------------
 * Sessions: a scene running
 *
 * open -> start -> poll ... -> stop -> destroy, or open -> run_stepped -> destroy. A session runs
 * once. stop() is idempotent; destroy() stops first and works from any state.
 * ------------------------------------------------------------------------------------------- */

/* Settings of one session (0 / NULL fields keep the scene's value). */
typedef struct uh_session_def {
  uint32_t struct_size;    /* sizeof(uh_session_def) */
  double haptic_hz;        /* override the haptic rate [Hz] (0: the scene's) */
  double collision_hz;     /* override the collision rate [Hz] (< 0: the scene's; 0 = free-running) */
  int32_t raise_priority;  /* nonzero: ask for SCHED_FIFO for the haptic and collision threads */
  const char* cache_dir;   /* where packed meshes are cached (NULL: $UH_CACHE_DIR or ~/.cache/unrealhaptics) */
  /* --- added in API version 2's second layout --- */
  int32_t proxy;           /* how contact is rendered: -1 the scene's (force.proxy, the 6-DOF proxy unless
                            * the scene turns it off), 0 the penalty path, 1 the 6-DOF proxy, which never
                            * lets the tool through a surface */
} uh_session_def;

UH_API uh_status uh_session_def_init(uh_session_def* def);
static inline uh_session_def uh_default_session_def(void) {
  uh_session_def def;
  memset(&def, 0, sizeof def);
  def.struct_size = (uint32_t)sizeof def;
  (void)uh_session_def_init(&def);
  return def;
}

/* The newest state of a tool, as its haptic thread sent it in its last tick. */
typedef struct uh_state {
  uint32_t struct_size;        /* sizeof(uh_state), set by the caller */
  double time_s;               /* that tick's time since start [s] (stepped: simulated time) */
  double tool_position[3];     /* the tool's mesh frame origin in the world [m] */
  double tool_orientation[4];  /* the tool's orientation in the world (w, x, y, z) */
  double force[3];             /* force sent to the device, world frame [N] */
  double torque[3];            /* torque sent to the device, world frame [N m] */
  int32_t contact_pairs;       /* sphere pairs the force of that tick used */
  uint64_t haptic_ticks;       /* haptic ticks since start */
  uint64_t missed_deadlines;   /* ticks that started more than a period late */
  double haptic_rate_hz;       /* haptic ticks per second over the last ~100 ms [Hz] */
  double collision_rate_hz;    /* collision steps per second over the last ~100 ms [Hz] */
  uint32_t buttons;            /* the device's buttons as read that tick (bit i: button i) */
  /* --- added in API version 2's second layout --- */
  double handle_position[3];   /* where the device's handle puts the tool's origin [m]: tool_position
                                * without a proxy; with one, the tool rests on the surface above it */
} uh_state;

/* A contact between a tool and a watched object began or ended. */
typedef int32_t uh_contact_kind;
enum { UH_CONTACT_BEGIN = 0, UH_CONTACT_END = 1 };

typedef struct uh_contact_event {
  uint32_t struct_size;  /* sizeof(uh_contact_event), set by the caller */
  uh_contact_kind kind;
  int32_t object;        /* index of the object in the scene */
  double time_s;         /* time of the collision step that saw it, since start [s] */
  double volume;         /* overlap volume then [m^3] (0 for UH_CONTACT_END; 0 through the proxy, which
                          * rests on the surface) */
  int32_t pairs;         /* overlapping sphere pairs then (0 for UH_CONTACT_END; through the proxy, its
                          * constraint rows in contact) */
  /* --- added in API version 2's second layout --- */
  int32_t tool;          /* index of the tool in the scene */
} uh_contact_event;

/* Called on the haptic thread after every tick (on the calling thread in stepped runs) with that
 * tick's state. Real-time: return within microseconds; no allocation, no locks, no blocking, no
 * calls into this API. `user` is the pointer given to uh_session_set_tick_callback. */
typedef void (*uh_tick_fn)(void* user, const uh_state* state);

/* Opens a session of the scene file `scene_path` (NULL: the embedded default scene): loads or
 * builds the trees, creates and opens the devices; starts no thread. Called through a macro that
 * passes this header's UH_API_VERSION; the function itself is exported for bindings, which
 * should compare uh_api_version() first. */
UH_API uh_status uh_session_open(const char* scene_path, uh_session_id* out);
UH_API uh_status uh_session_open_checked(int32_t api_version, const char* scene_path, uh_session_id* out);
#define uh_session_open(scene_path, out) uh_session_open_checked(UH_API_VERSION, (scene_path), (out))

/* Opens a session of a scene built through calls; `def` may be NULL (defaults). Same version
 * check as uh_session_open. */
UH_API uh_status uh_session_create(uh_scene_id scene, const uh_session_def* def, uh_session_id* out);
UH_API uh_status uh_session_create_checked(int32_t api_version, uh_scene_id scene, const uh_session_def* def,
                                           uh_session_id* out);
#define uh_session_create(scene, def, out) uh_session_create_checked(UH_API_VERSION, (scene), (def), (out))

/* Starts the haptic, collision and monitor threads and returns at once. */
UH_API uh_status uh_session_start(uh_session_id s);

/* Instead of start: runs `seconds` of the session on the calling thread in simulated time, one
 * collision step every `ticks_per_collision_step` haptic ticks (deterministic; for tests and
 * offline work). Returns when done; the session is then stopped. */
UH_API uh_status uh_session_run_stepped(uh_session_id s, double seconds, int32_t ticks_per_collision_step);

/* Copies the newest state of the (first) tool into `out` (out->struct_size set by the caller).
 * Any thread; never waits for the haptic thread. Before the first tick: zeros. After stop: the last state,
 * with the zero force the device got. */
UH_API uh_status uh_session_poll(uh_session_id s, uh_state* out);

/* Tools of the session's scene (each on its own device and haptic thread): their count, names
 * (valid until destroy) and each one's newest state, as uh_session_poll gives the first tool's
 * (`tool` from 0 to count - 1; any thread, never waits). */
UH_API uh_status uh_session_tool_count(uh_session_id s, int32_t* out);
UH_API uh_status uh_session_tool_name(uh_session_id s, int32_t tool, const char** out);
UH_API uh_status uh_session_tool_state(uh_session_id s, int32_t tool, uh_state* out);

/* Takes the oldest contact event not yet taken: *has_event is 1 and `out` filled, or 0 when none
 * is waiting. Events queue up (1024; more are dropped) from start on. */
UH_API uh_status uh_session_poll_event(uh_session_id s, uh_contact_event* out, int32_t* has_event);

/* Moves object `object` (its scene index) while the session runs; the collision thread uses the
 * pose from its next step. Call it for one object from one thread only. */
UH_API uh_status uh_session_set_object_pose(uh_session_id s, int32_t object, const double position[3],
                                            const double orientation[4]);

/* Sets (or with fn NULL removes) the haptic-thread tick callback of the first tool. Only before
 * start. */
UH_API uh_status uh_session_set_tick_callback(uh_session_id s, uh_tick_fn fn, void* user);

/* *out = 1 when the running session ended by itself: a device faulted, or a haptic, the collision
 * or a soft object's simulation thread ended (every device was sent zero at its next tick);
 * uh_session_stop then returns the cause (UH_ERROR_DEVICE or UH_ERROR_THREAD) and uh_last_error
 * says it. 0 while it runs as it should, before start and after stop. A host polls it, e.g. once
 * a frame, and stops the session when it is 1. */
UH_API uh_status uh_session_ended(uh_session_id s, int32_t* out);

/* Sends zero force at once, stops and joins every thread, completes the report. Idempotent: later
 * calls return what the first returned. UH_ERROR_THREAD if a thread had ended on its own,
 * UH_ERROR_DEVICE if a device faulted (the report is still complete). Before start: UH_OK,
 * nothing to do. */
UH_API uh_status uh_session_stop(uh_session_id s);

/* The report of the run as the JSON object `uh run --json` prints. Only after stop (or a stepped
 * run); `*out` stays valid until the session is destroyed. */
UH_API uh_status uh_session_report_json(uh_session_id s, const char** out);

/* Objects of the session's scene: their count and names (valid until destroy). */
UH_API uh_status uh_session_object_count(uh_session_id s, int32_t* out);
UH_API uh_status uh_session_object_name(uh_session_id s, int32_t object, const char** out);

/* Soft objects (scene `deformable`, docs/deformables.md): object `object`'s deformed surface, its
 * mesh refined so a dent shows. The vertex count, and the newest deformed vertices copied into
 * `xyz` (room for `capacity` vertices: 3 * capacity floats, x, y, z in metres in the object's
 * frame, as its mesh); `step`, when not NULL, gets the simulation step that made them (0: at
 * rest), so a caller sees whether they changed. The triangles (3 vertex indices each, counter-
 * clockwise from outside) never change: their count, and `indices` with room for `capacity`
 * triangles. Any thread, while the session runs or not; the simulation and haptic threads never
 * wait for it. UH_ERROR_INVALID_ARGUMENT for a rigid object or a buffer too small (the message
 * gives the count needed). */
UH_API uh_status uh_session_soft_vertex_count(uh_session_id s, int32_t object, int32_t* out);
UH_API uh_status uh_session_soft_vertices(uh_session_id s, int32_t object, float* xyz, int32_t capacity,
                                          uint64_t* step);
UH_API uh_status uh_session_soft_triangle_count(uh_session_id s, int32_t object, int32_t* out);
UH_API uh_status uh_session_soft_triangles(uh_session_id s, int32_t object, int32_t* indices, int32_t capacity);

/* Stops the session if it runs and destroys it. Zero, a stale id or a second destroy: nothing. */
UH_API void uh_session_destroy(uh_session_id s);

#ifdef __cplusplus
}
#endif

#endif /* UH_UH_H */
