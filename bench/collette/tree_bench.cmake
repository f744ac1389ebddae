# Sphere-tree queries against FCL and Bullet on the 69k-triangle bunny (from the shared assets).
uh_add_benchmark(uh_collette_query_bench SOURCES ${CMAKE_CURRENT_LIST_DIR}/query_bench.cpp
                 LIBRARIES uh::collette fcl PkgConfig::BULLET)
target_compile_definitions(uh_collette_query_bench PRIVATE UH_BENCH_CACHE_DIR="${CMAKE_CURRENT_BINARY_DIR}")

# Accuracy of the volume query against the sphere count (a plain program printing a table).
add_executable(uh_collette_query_accuracy ${CMAKE_CURRENT_LIST_DIR}/query_accuracy.cpp)
target_link_libraries(uh_collette_query_accuracy PRIVATE uh::collette)
target_compile_definitions(uh_collette_query_accuracy PRIVATE UH_ASSET_DIR="${PROJECT_SOURCE_DIR}/assets"
                                                             UH_SHARED_ASSET_DIR="${PROJECT_SOURCE_DIR}/../shared/assets")
target_include_directories(uh_collette_query_accuracy PRIVATE ${PROJECT_SOURCE_DIR}/tests/collette)
uh_target_warnings(uh_collette_query_accuracy)
