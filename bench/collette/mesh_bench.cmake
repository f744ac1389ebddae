uh_add_benchmark(uh_collette_packing_bench SOURCES ${CMAKE_CURRENT_LIST_DIR}/packing_bench.cpp LIBRARIES uh::collette)
