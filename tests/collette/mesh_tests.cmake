list(APPEND UH_COLLETTE_TEST_SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/mesh_import_test.cpp
  ${CMAKE_CURRENT_LIST_DIR}/mesh_inside_test.cpp
  ${CMAKE_CURRENT_LIST_DIR}/obj_stl_reader_test.cpp
  ${CMAKE_CURRENT_LIST_DIR}/packing_test.cpp
  ${CMAKE_CURRENT_LIST_DIR}/packing_preview_test.cpp
)
