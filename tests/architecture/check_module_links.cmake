# Checks the module graph as this build links it (LINKS, written at configure time by
# cmake/UhModuleGraph.cmake) against the allowed graph (ALLOWED, tests/architecture/module_links.txt):
# - every module of the build has a line in the allowed graph;
# - a module links exactly the uh modules its line names (of those this build has): a link the line
#   does not name is a dependency pointing where it should not, a named one it lacks is a stale line;
# - its other libraries are among those its line allows.
# usage: cmake -DLINKS=FILE -DALLOWED=FILE -P check_module_links.cmake
cmake_minimum_required(VERSION 3.25)

include(${CMAKE_CURRENT_LIST_DIR}/read_graph.cmake)

uh_read_graph(${LINKS} BUILT)
uh_read_graph(${ALLOWED} ALLOWED)
if(NOT BUILT_NAMES)
  message(FATAL_ERROR "${LINKS} lists no module: the build's module graph was not written")
endif()

# appends to `problems` a line per link of module `name` (of kind `what`) that its line does not name
macro(uh_check_named name what built allowed)
  foreach(link IN LISTS ${built})
    if(NOT link IN_LIST ${allowed})
      list(APPEND problems "'${name}' links ${what} '${link}', which its line in the allowed graph does not name")
    endif()
  endforeach()
endmacro()

set(problems "")
foreach(name IN LISTS BUILT_NAMES)
  if(NOT name IN_LIST ALLOWED_NAMES)
    list(APPEND problems "module '${name}' has no line in the allowed graph: add one with what it may link")
    continue()
  endif()
  uh_check_named(${name} "the module" BUILT_${name}_UH ALLOWED_${name}_UH)
  uh_check_named(${name} "the library" BUILT_${name}_OTHER ALLOWED_${name}_OTHER)
  foreach(dep IN LISTS ALLOWED_${name}_UH)
    if(dep IN_LIST BUILT_NAMES AND NOT dep IN_LIST BUILT_${name}_UH)
      list(APPEND problems "the allowed graph says '${name}' links '${dep}', but it does not: correct the line")
    endif()
  endforeach()
endforeach()

list(LENGTH BUILT_NAMES count)
if(problems)
  list(JOIN problems "\n  " text)
  message(FATAL_ERROR "the module graph breaks ${ALLOWED}:\n  ${text}")
endif()
message(STATUS "the ${count} modules of this build link as ${ALLOWED} allows")
