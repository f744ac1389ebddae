# mesh import, validation, distance fields, sphere packing, previews
list(APPEND UH_COLLETTE_SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/triangle_mesh.cpp
  ${CMAKE_CURRENT_LIST_DIR}/triangle_bvh.cpp
  ${CMAKE_CURRENT_LIST_DIR}/mesh_import.cpp
  ${CMAKE_CURRENT_LIST_DIR}/obj_stl_reader.cpp
  ${CMAKE_CURRENT_LIST_DIR}/mesh_json.cpp
  ${CMAKE_CURRENT_LIST_DIR}/mesh_inside.cpp
  ${CMAKE_CURRENT_LIST_DIR}/sphere_grid.cpp
  ${CMAKE_CURRENT_LIST_DIR}/sphere_packing.cpp
)
# load_mesh() reads through assimp where the build has it, else with the in-tree OBJ/STL reader
if(TARGET assimp::assimp)
  list(APPEND UH_COLLETTE_SOURCES ${CMAKE_CURRENT_LIST_DIR}/mesh_file_assimp.cpp)
else()
  list(APPEND UH_COLLETTE_SOURCES ${CMAKE_CURRENT_LIST_DIR}/mesh_file_builtin.cpp)
endif()
# packing previews need libpng; the uh program is their only user (not in the Windows build)
if(TARGET PNG::PNG)
  list(APPEND UH_COLLETTE_SOURCES ${CMAKE_CURRENT_LIST_DIR}/packing_preview.cpp)
endif()
