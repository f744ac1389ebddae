# mesh import, validation, distance fields, sphere packing, previews
list(APPEND UH_COLLETTE_SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/triangle_mesh.cpp
  ${CMAKE_CURRENT_LIST_DIR}/triangle_bvh.cpp
  ${CMAKE_CURRENT_LIST_DIR}/mesh_import.cpp
  ${CMAKE_CURRENT_LIST_DIR}/mesh_inside.cpp
  ${CMAKE_CURRENT_LIST_DIR}/sphere_grid.cpp
  ${CMAKE_CURRENT_LIST_DIR}/sphere_packing.cpp
  ${CMAKE_CURRENT_LIST_DIR}/packing_preview.cpp
)
