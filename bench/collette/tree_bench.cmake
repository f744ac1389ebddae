# Sphere-tree queries against FCL and Bullet on the 69k-triangle bunny (from the shared assets).
uh_add_benchmark(uh_collette_query_bench SOURCES ${CMAKE_CURRENT_LIST_DIR}/query_bench.cpp
                 LIBRARIES uh::collette fcl PkgConfig::BULLET)
target_compile_definitions(uh_collette_query_bench PRIVATE UH_BENCH_CACHE_DIR="${CMAKE_CURRENT_BINARY_DIR}")
