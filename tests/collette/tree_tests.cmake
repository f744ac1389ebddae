list(APPEND UH_COLLETTE_TEST_SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/tree_builder_test.cpp
  ${CMAKE_CURRENT_LIST_DIR}/tree_rebuild_test.cpp
  ${CMAKE_CURRENT_LIST_DIR}/query_volume_test.cpp
  ${CMAKE_CURRENT_LIST_DIR}/query_time_critical_test.cpp
  ${CMAKE_CURRENT_LIST_DIR}/query_distance_test.cpp
  ${CMAKE_CURRENT_LIST_DIR}/query_alloc_test.cpp
  ${CMAKE_CURRENT_LIST_DIR}/ist_file_test.cpp
  ${CMAKE_CURRENT_LIST_DIR}/ist_surface_test.cpp
  ${CMAKE_CURRENT_LIST_DIR}/ist_cache_test.cpp
  ${CMAKE_CURRENT_LIST_DIR}/query_accuracy_test.cpp
  ${CMAKE_CURRENT_LIST_DIR}/query_margin_test.cpp
  ${CMAKE_CURRENT_LIST_DIR}/query_coherence_test.cpp
)
