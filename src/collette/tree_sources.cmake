# sphere trees, .ist files, queries, collision world
list(APPEND UH_COLLETTE_SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/sphere_tree.cpp
  ${CMAKE_CURRENT_LIST_DIR}/sphere_tree_builder.cpp
  ${CMAKE_CURRENT_LIST_DIR}/volume_query.cpp
  ${CMAKE_CURRENT_LIST_DIR}/volume_query_avx2.cpp
  ${CMAKE_CURRENT_LIST_DIR}/volume_query_avx512.cpp
  ${CMAKE_CURRENT_LIST_DIR}/time_critical_query.cpp
  ${CMAKE_CURRENT_LIST_DIR}/distance_query.cpp
  ${CMAKE_CURRENT_LIST_DIR}/ist_file.cpp
)
