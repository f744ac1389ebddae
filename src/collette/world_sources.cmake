# the collision world and its thread
list(APPEND UH_COLLETTE_SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/collision_world.cpp
  ${CMAKE_CURRENT_LIST_DIR}/dynamic_aabb_tree.cpp
  ${CMAKE_CURRENT_LIST_DIR}/ist_builder.cpp
  ${CMAKE_CURRENT_LIST_DIR}/ist_cache.cpp
)
