/*
 * uh_v2_0_structs.h: the structs of uh.h as API version 2 first published them, frozen (a header
 * snapshot, plain C99). The library reads the sizes of these older layouts to accept an older
 * program's smaller struct_size; the C API's test compiles an older caller from them
 * (tests/capi/capi_test.c, "older_caller"). Never edit a struct here: when uh.h's struct grows,
 * its older layout stays here as it was. The ids (uh_tree_id, ...) are uh.h's.
 */
#ifndef UH_V2_0_STRUCTS_H
#define UH_V2_0_STRUCTS_H

#include "uh/uh.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct uh_v2_0_tree_build_def {
  uint32_t struct_size;
  int64_t spheres;
  double meters_per_unit;
} uh_v2_0_tree_build_def;

typedef struct uh_v2_0_shape_def {
  uint32_t struct_size;
  const char* mesh_path;
  const char* ist_path;
  uh_tree_id tree;
  const double* vertices;
  int32_t vertex_count;
  const int32_t* indices;
  int32_t triangle_count;
  int64_t spheres;
  double meters_per_unit;
} uh_v2_0_shape_def;

typedef struct uh_v2_0_object_def {
  uint32_t struct_size;
  const char* name;
  uh_v2_0_shape_def shape;
  double position[3];
  double orientation[4];
  int32_t watch;
} uh_v2_0_object_def;

typedef struct uh_v2_0_tool_def {
  uint32_t struct_size;
  const char* name;
  uh_v2_0_shape_def shape;
  int32_t mode;
  int32_t law;
  double stiffness;
  double force_scale;
  double damping;
  double damping_full_volume;
  double mass_kg;
  double center_of_mass[3];
  double max_force_n;
  double max_torque_nm;
  const char* device_driver;
  const char* device_config_json;
  double workspace_scale;
  double workspace_offset[3];
  double workspace_rotation[4];
} uh_v2_0_tool_def;

typedef struct uh_v2_0_session_def {
  uint32_t struct_size;
  double haptic_hz;
  double collision_hz;
  int32_t raise_priority;
  const char* cache_dir;
} uh_v2_0_session_def;

typedef struct uh_v2_0_state {
  uint32_t struct_size;
  double time_s;
  double tool_position[3];
  double tool_orientation[4];
  double force[3];
  double torque[3];
  int32_t contact_pairs;
  uint64_t haptic_ticks;
  uint64_t missed_deadlines;
  double haptic_rate_hz;
  double collision_rate_hz;
  uint32_t buttons;
} uh_v2_0_state;

typedef struct uh_v2_0_contact_event {
  uint32_t struct_size;
  int32_t kind;
  int32_t object;
  double time_s;
  double volume;
  int32_t pairs;
} uh_v2_0_contact_event;

typedef struct uh_v2_0_tree_info {
  uint32_t struct_size;
  int32_t leaf_count;
  double coverage;
  double mesh_volume;
  double center[3];
  double radius;
} uh_v2_0_tree_info;

typedef struct uh_v2_0_query_result {
  uint32_t struct_size;
  double volume;
  double volume_estimate;
  double direction[3];
  int32_t pair_count;
  double distance;
} uh_v2_0_query_result;

#ifdef __cplusplus
}
#endif

#endif /* UH_V2_0_STRUCTS_H */
