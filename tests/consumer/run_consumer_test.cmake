# cmake -P script run by the consumer.installed_package test (see CMakeLists.txt next to it).
# Inputs: UH_BUILD_DIR, UH_CONSUMER_SOURCE_DIR, UH_WORK_DIR, UH_GENERATOR, UH_CXX_COMPILER, UH_BUILD_TYPE.
cmake_minimum_required(VERSION 3.25)

foreach(var UH_BUILD_DIR UH_CONSUMER_SOURCE_DIR UH_WORK_DIR UH_GENERATOR UH_CXX_COMPILER)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "run_consumer_test.cmake: ${var} is not set")
  endif()
endforeach()
if(NOT UH_BUILD_TYPE)
  set(UH_BUILD_TYPE Release)
endif()

set(prefix "${UH_WORK_DIR}/prefix")
set(consumer_build "${UH_WORK_DIR}/build")
file(REMOVE_RECURSE "${UH_WORK_DIR}")
file(MAKE_DIRECTORY "${UH_WORK_DIR}")

function(run_step name)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "consumer test: ${name} failed (${rc})\n${out}\n${err}")
  endif()
  message(STATUS "consumer test: ${name} done")
  set(step_output "${out}" PARENT_SCOPE)
endfunction()

run_step("install into ${prefix}"
  ${CMAKE_COMMAND} --install "${UH_BUILD_DIR}" --prefix "${prefix}")
# the consumer sees the installed package only: no source tree, no build tree
run_step("configure the consumer"
  ${CMAKE_COMMAND} -S "${UH_CONSUMER_SOURCE_DIR}" -B "${consumer_build}" -G "${UH_GENERATOR}"
    "-DCMAKE_PREFIX_PATH=${prefix}" "-DCMAKE_CXX_COMPILER=${UH_CXX_COMPILER}"
    "-DCMAKE_BUILD_TYPE=${UH_BUILD_TYPE}" -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF)
run_step("build the consumer" ${CMAKE_COMMAND} --build "${consumer_build}")

find_program(consumer_exe uh_consumer PATHS "${consumer_build}" NO_DEFAULT_PATH REQUIRED)
run_step("run the consumer" "${consumer_exe}")
message("${step_output}")
if(NOT step_output MATCHES "consumer ok")
  message(FATAL_ERROR "consumer test: the consumer did not report success")
endif()

find_program(capi_consumer_exe uh_capi_consumer PATHS "${consumer_build}" NO_DEFAULT_PATH REQUIRED)
run_step("run the C API consumer" "${capi_consumer_exe}")
message("${step_output}")
if(NOT step_output MATCHES "capi consumer ok")
  message(FATAL_ERROR "consumer test: the C API consumer did not report success")
endif()
