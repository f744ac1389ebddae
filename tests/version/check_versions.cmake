# cmake -P script of the version.agree test: everything that states the release's version states
# project(VERSION) of the top-level CMakeLists.txt, the one place a release bumps it.
# Inputs: UH_VERSION, UH_CLI (may be empty), UH_PYTHON and UH_PYTHON_DIR (may be empty),
# UH_UNITY_MANIFEST, UH_GODOT_MANIFEST.
cmake_minimum_required(VERSION 3.25)
set(errors "")

function(expect what found)
  if(NOT found STREQUAL UH_VERSION)
    set(errors "${errors}\n  ${what} says '${found}', project(VERSION) says '${UH_VERSION}'" PARENT_SCOPE)
  endif()
endfunction()

file(READ "${UH_UNITY_MANIFEST}" unity_json)
string(JSON unity_version ERROR_VARIABLE json_error GET "${unity_json}" version)
expect("${UH_UNITY_MANIFEST} (version)" "${unity_version}")

file(STRINGS "${UH_GODOT_MANIFEST}" godot_line REGEX "^version=")
string(REGEX REPLACE "^version=\"(.*)\"$" "\\1" godot_version "${godot_line}")
expect("${UH_GODOT_MANIFEST} (version=)" "${godot_version}")

if(UH_CLI)
  execute_process(COMMAND "${UH_CLI}" --version OUTPUT_VARIABLE out RESULT_VARIABLE rc OUTPUT_STRIP_TRAILING_WHITESPACE)
  string(REGEX REPLACE "^uh " "" out "${out}")
  expect("uh --version (exit ${rc})" "${out}")
endif()

if(UH_PYTHON_DIR)
  execute_process(COMMAND ${CMAKE_COMMAND} -E env "PYTHONPATH=${UH_PYTHON_DIR}"
                  "${UH_PYTHON}" -c "import unrealhaptics; print(unrealhaptics.__version__)"
                  OUTPUT_VARIABLE out RESULT_VARIABLE rc OUTPUT_STRIP_TRAILING_WHITESPACE)
  expect("unrealhaptics.__version__ (exit ${rc})" "${out}")
endif()

if(errors)
  message(FATAL_ERROR "version mismatch:${errors}\nEdit the files above to the project's version.")
endif()
message(STATUS "version ${UH_VERSION}: uh, the Python module, the Unity and Godot manifests agree")
