# The collision world and the volume query's worker thread run threads: their tests form a second
# executable labelled "threads", so that the README's test command also runs them under
# ThreadSanitizer.
uh_add_test_executable(uh_collette_world_tests
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/collision_world_test.cpp
          ${CMAKE_CURRENT_LIST_DIR}/query_worker_test.cpp
  LIBRARIES uh::collette
  LABELS threads)
